// Direct lighting of many hits on one material at once, in SIMD lanes (Google Highway, as
// render/ggx_batch.h): the shadow rays a hit casts and their values, made slot by slot over a tile's hits
// instead of one hit at a time, which would spend a large share of a sphere's render on making the
// requests, the BRDF samples' directions and the shadow rays' values (docs/render-speed.md).
//
// Per hit the slots are, in this order: the environment's light sample (a map's; a constant environment
// has none, render/integrator.cpp), the BRDF sample (with an environment), then each light. A slot that
// lights nothing (below the horizon, no direction found) casts no ray. The renderer adds a hit's unblocked rays in slot order, as its one-ray-at-a-time path does.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "render/shading_batch.h"
#include "render/sphere_batch.h"
#include "render/simd_targets.h"
#include "render/tracer.h"

namespace facetfit {

// A tile's camera rays for one sample index, per pixel, in columns: the hit (t, infinity for none; the
// material's index, -1 for none; a sphere's centre and the reciprocal of its radius, or a triangle's normal
// and 0, in g and inv_radius), the environment's light sample (world direction, density, radiance), and
// the ray's direction and the BRDF sample's numbers.
struct TileHits : Columns {
  std::vector<double> t, material, inv_radius, gx, gy, gz;
  std::vector<double> lx, ly, lz, light_pdf, light_r, light_g, light_b;
  // The directions and numbers: columns the caller owns (the camera samples', read in place, not copied
  // here), readable to padded_size().
  const double *dx = nullptr, *dy = nullptr, *dz = nullptr, *u1 = nullptr, *u2 = nullptr, *u3 = nullptr;
  // Whether the environment's light sample columns (lx ... light_b) hold one: a map's. Without, they are
  // not read, and place_hits() does not pass them on.
  bool light_sampled = false;
  // n pixels, whose columns the caller writes in place.
  void resize_to(std::size_t n) {
    ensure(n, [this](std::size_t m) {
      resize({&t, &material, &inv_radius, &gx, &gy, &lx, &ly, &light_r, &light_g, &light_b}, m, 0.0);
      resize({&gz, &lz, &light_pdf}, m, 1.0);
    });
    set_size(n);
  }
};

// Per object of a scene, what the lanes read of a hit on it: its material's index where the lanes shade
// that material (-1 where it is shaded one hit at a time), and a sphere's centre and the reciprocal of its
// radius (0 for a mesh).
struct LaneObjects {
  std::vector<double> material, cx, cy, cz, inv_radius;
};

// The tile's columns of its camera rays' hits (t, material, inv_radius, g) from the tracer's, for their
// padded_size() entries: material -1 where a ray hit nothing or an object shaded one hit at a time. Per
// pixel also alpha (1 where its ray hit something, else 0) and radiance (r, g, b: `background` where its
// ray hit nothing, else 0). Per vector of rays, the lookups of one object where every lane that hit
// something hit it (the inside of a sphere and its outline), lane by lane otherwise.
void take_hits(const RayHits& hits, const LaneObjects& objects, const Rgb& background, TileHits& tile, double* alpha,
               double* const radiance[3], SimdTarget target = SimdTarget::best);

// The hits on one material, for one sample index, in columns: the shading frame, the hit and the shadow
// rays' origin, the environment's light sample, the pixel's index in the tile (owner), and the BRDF
// sampler's batch (`draws`): its inputs are the direction toward the camera in the frame and the BRDF
// sample's numbers, its outputs are drawn in place.
struct HitBatch : Columns {
  std::vector<double> tx, ty, tz, bx, by, bz, nx, ny, nz;
  std::vector<double> px, py, pz;  // only where `positions` (place_hits() was asked for them)
  bool positions = false;
  std::vector<double> origin_x, origin_y, origin_z;
  std::vector<double> lx, ly, lz, light_pdf, light_r, light_g, light_b;
  std::vector<double> owner;  // exact in a double
  SampleBatch draws;          // as many entries as hits
  bool light_sampled = false;  // TileHits::light_sampled, passed on: without, lx ... light_b are not written

  // Room for n hits written in place by the lanes; size() stays.
  void reserve(std::size_t n) {
    ensure(n, [this](std::size_t m) {
      resize({&tx, &ty, &bx, &by, &nx, &ny, &px, &py, &pz, &origin_x, &origin_y, &origin_z, &lx, &ly, &light_r, &light_g, &light_b, &owner},
             m, 0.0);
      resize({&tz, &bz, &nz, &lz, &light_pdf}, m, 1.0);
    });
    draws.reserve(n);
  }
  void set_size(std::size_t n) { Columns::set_size(n), draws.resize_to(n); }
  void clear() { Columns::clear(), draws.clear(), positions = false, light_sampled = false; }
};

// Fills `out` with the tile's hits on material `material` (emptied first), as the renderer's one-hit path
// places a hit: p = camera + t d; the normal from the sphere's centre or the triangle's, turned toward the
// camera; the frame of core/frame.h about it (along `tangent` where given); o the direction toward the
// camera in it; the shadow rays' origin p + eps n. p itself only with `positions` (point lights read it):
// each column a hit carries costs its compaction, so those a scene does not read are skipped (p; the light
// sample's direction, density and radiance where the environment has none).
void place_hits(const TileHits& tile, const Vec3& camera, double eps, double material, const Vec3* tangent, bool positions,
                HitBatch& out, SimdTarget target = SimdTarget::best);

// A light as the lanes read it: directional (vector toward it) or a point (its position), and what it
// sends (irradiance, or intensity at unit distance).
struct LaneLight {
  bool directional;
  double x, y, z;
  double r, g, b;
};

// The evaluations the slots need (the EvaluationBatch a material's eval() fills) and, per evaluation, its
// shadow ray (from the hit's shadow-ray origin along the world direction, up to the light), the radiance
// arriving along it if nothing blocks it, the environment's density of the direction (0 for a light, and
// for a BRDF sample under a constant environment, which has no light sample) and
// the pixel it lights (its hit's owner). Afterwards value (r, g, b) and whether the slot casts a ray at
// all.
struct ShadowBatch : EvaluationBatch {
  RayBatch rays;
  std::vector<double> arriving_r, arriving_g, arriving_b, light_pdf, owner;
  std::vector<double> value_r, value_g, value_b, casts;
  // Room for n entries written in place by the lanes; size() stays.
  void reserve(std::size_t n) {
    rays.reserve(n);
    ensure(n, [this](std::size_t m) {
      grow(m);
      resize({&arriving_r, &arriving_g, &arriving_b, &light_pdf, &owner, &value_r, &value_g, &value_b, &casts}, m, 0.0);
    });
  }
  void set_size(std::size_t n) { Columns::set_size(n), rays.set_size(n); }
};

// The ranges of a ShadowBatch's entries by slot: the environment's light samples [0, lights_begin), the
// lights' [lights_begin, brdf_begin) light by light (light j's from light_begin[j]), the BRDF samples'
// [brdf_begin, size()).
struct SlotRanges {
  std::size_t lights_begin = 0, brdf_begin = 0;
  std::vector<std::size_t> light_begin;
};

// Appends to `out` (emptied first) the evaluations of the environment's light samples (where the hits hold
// them: light_sampled) and of the lights, for the hits' padded_size() entries, and the ranges.
// The shadow rays start at the hits' origins and ignore what lies nearer than `tnear`.
void light_slots(const HitBatch& hits, const std::vector<LaneLight>& lights, double tnear, ShadowBatch& out, SlotRanges& ranges,
                 SimdTarget target = SimdTarget::best);

// Appends the BRDF samples found (hits.draws, drawn) as evaluations with their world directions, arriving
// `radiance` at environment density 0: a constant environment's, which no light sample weighs them
// against (the caller replaces both under a map).
void brdf_slots(const HitBatch& hits, const Rgb& radiance, double tnear, ShadowBatch& out, SimdTarget target = SimdTarget::best);

// The value of each entry's shadow ray from its evaluation (ShadowBatch::r, g, b, pdf), as the one-hit
// path computes it: multiple importance sampling by the power heuristic for the environment's light and
// BRDF samples (a BRDF sample weighs 1 where its direction's environment density is 0), a light's value
// times the cosine; casts 0 for a BRDF sample of zero density.
void shadow_values(ShadowBatch& batch, const SlotRanges& ranges, SimdTarget target = SimdTarget::best);

// A sample's radiance and alpha added to each of n pixels' sums, as the renderer's one-ray path adds them:
// sum[c][k] += radiance[c][k] (c = r, g, b) where all three are finite, nothing where one is not, and
// sum[3][k] += alpha[k].
void add_samples(const double* const radiance[3], const double* alpha, double* const sum[4], std::size_t n,
                 SimdTarget target = SimdTarget::best);

}  // namespace facetfit
