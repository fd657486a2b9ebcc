// Rays: the sphere's closed form and its SIMD lanes, spheres and triangles in one tracer, the wavefront's
// hits, light and BRDF slots and sample sums in lanes against the one-hit path, and the camera's samples
// in lanes against one at a time.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/frame.h"
#include "render/camera_batch.h"
#include "render/scene.h"
#include "render/simd_targets.h"
#include "render/sphere_batch.h"
#include "render/tracer.h"
#include "render/wavefront.h"

namespace facetfit {
namespace {

TEST(Tracer, SphereRootsStayAccurateFarAwayAndAtGrazingAngles) {
  const Vec3 c(0.0, 0.0, 0.0);
  // Far away: 1e6 units off, the root is 1e6 - 1 to a relative 1e-12 (b^2 - ac would lose half the digits).
  EXPECT_NEAR(intersect_sphere(c, 1.0, Ray{Vec3(0, 0, 1e6), Vec3(0, 0, -1)}), 1e6 - 1.0, 1e-6);
  // An unnormalized direction: t is in its units.
  EXPECT_NEAR(intersect_sphere(c, 1.0, Ray{Vec3(0, 0, 5), Vec3(0, 0, -2)}), 2.0, 1e-12);
  // From inside: the exit; from the surface outward past tnear: nothing; a line passing at 1 + 1e-9: nothing.
  EXPECT_NEAR(intersect_sphere(c, 2.0, Ray{Vec3(0.5, 0, 0), Vec3(1, 0, 0)}), 1.5, 1e-12);
  EXPECT_TRUE(std::isinf(intersect_sphere(c, 1.0, Ray{Vec3(0, 0, 1.0002), glm::normalize(Vec3(1, 0, 1e-3)), 2e-4})));
  EXPECT_TRUE(std::isinf(intersect_sphere(c, 1.0, Ray{Vec3(-5, 1.0 + 1e-9, 0), Vec3(1, 0, 0)})));
  // Grazing at 1 - 1e-6: the two roots are 2.8e-3 apart, both found.
  const Ray graze{Vec3(-5, 1.0 - 1e-6, 0), Vec3(1, 0, 0)};
  const double half_chord = std::sqrt(1.0 - (1.0 - 1e-6) * (1.0 - 1e-6));
  EXPECT_NEAR(intersect_sphere(c, 1.0, graze), 5.0 - half_chord, 1e-12);
  EXPECT_NEAR(intersect_sphere(c, 1.0, Ray{graze.origin, graze.dir, 5.0}), 5.0 + half_chord, 1e-12);
  // Beyond tfar: nothing.
  EXPECT_TRUE(std::isinf(intersect_sphere(c, 1.0, Ray{Vec3(0, 0, 5), Vec3(0, 0, -1), 0.0, 3.9})));
  // Outside and moving away (the early exit): nothing ahead; with tnear behind the origin, the roots
  // behind it are still found.
  EXPECT_TRUE(std::isinf(intersect_sphere(c, 1.0, Ray{Vec3(0, 0, 5), Vec3(0, 0.6, 0.8)})));
  EXPECT_NEAR(intersect_sphere(c, 1.0, Ray{Vec3(0, 0, 5), Vec3(0, 0, 1), -10.0}), -6.0, 1e-12);
}

// The lanes answer each ray as intersect_sphere does: the same sphere, the same blocking and t to rounding
// (GCC fuses the AVX2 code's multiply-adds), for rays from outside, inside, on the surface leaving it
// (shadow rays, tnear > 0), grazing, bounded by tfar; both SIMD targets, and batch sizes that leave
// partial vectors.
TEST(Tracer, SpheresInLanesEqualTheClosedForm) {
  SphereSet spheres;
  const std::vector<std::pair<Vec3, double>> list = {{Vec3(0, 0, 0), 1.0}, {Vec3(1.5, 0.2, -0.3), 0.5}, {Vec3(-2, 1, 1), 0.25}};
  // Ids other than the indices, as the tracer's object indices may be.
  for (const auto& [c, r] : list)
    spheres.cx.push_back(c.x), spheres.cy.push_back(c.y), spheres.cz.push_back(c.z), spheres.radius.push_back(r),
        spheres.id.push_back(double(10 + spheres.id.size()));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto direction = [&] {
    Vec3 v;
    do v = Vec3(u(rng), u(rng), u(rng));
    while (glm::length(v) < 0.1 || glm::length(v) > 1.0);
    return glm::normalize(v);
  };
  for (const std::size_t n : {1, 3, 4, 5, 17, 400}) {
    RayBatch rays;
    std::vector<Ray> scalar;
    for (std::size_t k = 0; k < n; ++k) {
      Ray r;
      switch (k % 4) {
        case 0: r = Ray(3.0 * direction(), direction()); break;                        // from outside, anywhere
        case 1: r = Ray(0.5 * direction(), direction(), 0.0, 0.5 + 2.0 * std::abs(u(rng))); break;  // inside, bounded
        case 2: {                                                                        // leaving the unit sphere
          const Vec3 n0 = direction();
          Vec3 d = direction();
          if (glm::dot(d, n0) < 0.0) d = -d;
          r = Ray(n0 * (1.0 + 2e-4), d, 2e-4);
          break;
        }
        default: r = Ray(Vec3(-5, 1.0 - 1e-7 * std::abs(u(rng)), 0), Vec3(1, 0, 0)); break;  // grazing
      }
      scalar.push_back(r);
      rays.push(r.origin, r.dir, r.tnear, r.tfar);
    }
    for (const SimdTarget target : kSimdTargets) {
      std::vector<double> t;
      std::vector<double> which;
      std::vector<char> blocked(n, 0);
      nearest_spheres(spheres, rays, t, which, target);
      blocked_by_spheres(spheres, rays, blocked, target);
      for (std::size_t k = 0; k < n; ++k) {
        double best = std::numeric_limits<double>::infinity();
        int nearest = -1;
        bool any = false;
        Ray bounded = scalar[k];
        for (std::size_t s = 0; s < list.size(); ++s) {
          const double ts = intersect_sphere(list[s].first, list[s].second, bounded);
          if (ts < bounded.tfar) bounded.tfar = best = ts, nearest = int(s);
          any = any || std::isfinite(intersect_sphere(list[s].first, list[s].second, scalar[k]));
        }
        EXPECT_EQ(which[k], nearest >= 0 ? 10.0 + nearest : -1.0) << n << " " << k << " " << simd_target_name(target);
        if (nearest >= 0) {
          EXPECT_NEAR(t[k], best, 1e-14 * best) << n << " " << k << " " << simd_target_name(target);
        }
        EXPECT_EQ(bool(blocked[k]), any) << n << " " << k << " " << simd_target_name(target);
      }
    }
    // Rays from one point (a camera's: outside every sphere, and inside the first), as the closed form.
    for (const Vec3 origin : {Vec3(0.3, 0.4, 4.0), Vec3(0.1, -0.2, 0.3)}) {
      std::vector<double> dx, dy, dz;
      for (std::size_t k = 0; k < rays.padded_size(); ++k) {
        // Toward the spheres, or anywhere.
        const Vec3 v = k % 2 ? glm::normalize(list[k % 3].first + 0.5 * direction() - origin) : direction();
        dx.push_back(v.x), dy.push_back(v.y), dz.push_back(v.z);
      }
      for (const SimdTarget target : kSimdTargets) {
        std::vector<double> t, which;
        nearest_spheres(spheres, RaysFromPoint{origin, dx.data(), dy.data(), dz.data(), n}, t, which, target);
        for (std::size_t k = 0; k < n; ++k) {
          Ray ray(origin, Vec3(dx[k], dy[k], dz[k]));
          int nearest = -1;
          for (std::size_t s = 0; s < list.size(); ++s) {
            const double ts = intersect_sphere(list[s].first, list[s].second, ray);
            if (ts < ray.tfar) ray.tfar = ts, nearest = int(s);
          }
          EXPECT_EQ(which[k], nearest >= 0 ? 10.0 + nearest : -1.0) << n << " " << k << " " << simd_target_name(target);
          if (nearest >= 0) {
            EXPECT_NEAR(t[k], ray.tfar, 1e-14 * ray.tfar) << n << " " << k << " " << simd_target_name(target);
          }
        }
      }
    }
  }
}

TEST(Tracer, SpheresAndTrianglesTogether) {
  const SceneDesc s = parse_scene_text(R"({
    "materials": {"m": {"type": "lambert"}},
    "objects": [{"type": "sphere", "center": [0, 1, 0], "radius": 0.5, "material": "m"},
                {"type": "sphere", "center": [0, 3, 0], "radius": 0.5, "material": "m"},
                {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "size": 4, "material": "m"}]
  })", "tracer.json", ".");
  const Tracer tracer(s);
  const Ray down{Vec3(0, 5, 0), Vec3(0, -1, 0)}, beside{Vec3(1, 5, 0), Vec3(0, -1, 0)}, outside{Vec3(3, 5, 0), Vec3(0, -1, 0)};
  EXPECT_EQ(tracer.intersect(down).object, 1);  // the upper sphere first
  EXPECT_NEAR(tracer.intersect(down).t, 1.5, 1e-12);
  EXPECT_EQ(tracer.intersect(beside).object, 2);  // the plane, a triangle hit
  EXPECT_NEAR(tracer.intersect(beside).t, 5.0, 1e-5);
  EXPECT_FALSE(tracer.intersect(outside).found());
  EXPECT_TRUE(tracer.occluded(down));
  EXPECT_FALSE(tracer.occluded(Ray{Vec3(0, 5, 0), Vec3(0, -1, 0), 0.0, 1.4}));  // stops short of the sphere
  EXPECT_TRUE(tracer.occluded(beside));
  EXPECT_FALSE(tracer.occluded(Ray{Vec3(1, 5, 0), Vec3(0, -1, 0), 0.0, 4.9}));
  // The streams answer as the one-ray queries do.
  const std::vector<Ray> rays = {down, beside, outside, Ray{Vec3(0, 5, 0), Vec3(0, -1, 0), 0.0, 1.4}};
  std::vector<Hit> hits;
  std::vector<char> blocked;
  tracer.intersect(rays, hits, true);
  tracer.occluded(rays, blocked);
  for (std::size_t k = 0; k < rays.size(); ++k) {
    EXPECT_EQ(hits[k].object, tracer.intersect(rays[k]).object) << k;
    EXPECT_EQ(bool(blocked[k]), tracer.occluded(rays[k])) << k;
  }
}

// The lanes' hits and slots (render/wavefront.h) on every SIMD target against the one-hit path's
// arithmetic: each hit placed as Frame (core/frame.h) places it, with and without a tangent, on spheres
// and triangles; each light's and the environment's slot where it lights the hit and nowhere else, with
// its direction in the frame, its ray and what arrives along it. Both with a light sample's radiance and
// density per hit (a map's) and a point light (which reads the hits' positions), and with no light sample
// (a constant environment's: no slot of its own, BRDF samples weighing 1) and a directional light alone
// (no positions). Then the slots' values against the one-hit path's formulas.
TEST(Wavefront, HitsAndSlotsEqualTheOneHitPath) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto unit = [&] { return glm::normalize(Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5) + Vec3(1e-3)); };
  const Vec3 camera(0.2, 0.5, 4.0), tangent(0.3, 1.0, 0.2);
  const double eps = 2e-4;
  for (const auto& [constant, n] : {std::pair<bool, std::size_t>{false, 1}, {false, 5}, {false, 37}, {true, 1}, {true, 5}, {true, 37}}) {
    std::vector<LaneLight> lights = {{true, 0.3, 1.0, 0.5, 3, 2, 1}};
    if (!constant) lights.push_back({false, -2.0, 3.0, 1.0, 5, 4, 3});
    TileHits tile;
    tile.resize_to(n);
    // The directions and numbers the tile reads in place, padded (finite past n).
    std::vector<double> dx(tile.padded_size(), 0.0), dy(tile.padded_size(), 0.0), dz(tile.padded_size(), 1.0);
    std::vector<double> u1(tile.padded_size(), 0.5), u2(tile.padded_size(), 0.5), u3(tile.padded_size(), 0.5);
    tile.dx = dx.data(), tile.dy = dy.data(), tile.dz = dz.data(), tile.u1 = u1.data(), tile.u2 = u2.data(), tile.u3 = u3.data();
    // Constant: the light sample's columns hold something (not to be read).
    tile.light_sampled = !constant;
    for (std::size_t k = 0; k < n; ++k) {
      const Vec3 d = glm::normalize(Vec3(u(rng) - 0.5, u(rng) - 0.5, -4.0));
      dx[k] = d.x, dy[k] = d.y, dz[k] = d.z;
      tile.t[k] = 3.0 + u(rng), tile.material[k] = double(k % 3 == 2 ? 1 : 0);
      const Vec3 g = k % 2 ? Vec3(u(rng), u(rng), -u(rng)) : unit();  // a centre, or a triangle's normal
      // A sphere through the hit: its radius the centre's distance from it.
      tile.inv_radius[k] = k % 2 ? 1.0 / glm::length(camera + tile.t[k] * d - g) : 0.0;
      tile.gx[k] = g.x, tile.gy[k] = g.y, tile.gz[k] = g.z;
      const Vec3 l = unit();
      tile.lx[k] = l.x, tile.ly[k] = l.y, tile.lz[k] = l.z, tile.light_pdf[k] = k % 5 ? 0.1 : 0.0;
      tile.light_r[k] = 0.1 * double(k % 4), tile.light_g[k] = 0.2, tile.light_b[k] = 0.1;
      u1[k] = u(rng), u2[k] = u(rng), u3[k] = u(rng);
    }
    for (const bool with_tangent : {false, true})
      for (const SimdTarget target : kSimdTargets) {
        const std::string where = std::to_string(n) + (with_tangent ? " tangent " : " ") + (constant ? "constant " : "") + simd_target_name(target);
        HitBatch hits;
        place_hits(tile, camera, eps, 0.0, with_tangent ? &tangent : nullptr, !constant, hits, target);
        ShadowBatch slots;
        SlotRanges ranges;
        if (constant) {
          EXPECT_THROW(light_slots(hits, {{false, -2.0, 3.0, 1.0, 5, 4, 3}}, eps, slots, ranges, target), std::invalid_argument);
        }
        light_slots(hits, lights, eps, slots, ranges, target);
        const auto close = [](double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(1.0, std::abs(b)); };
        // The one-hit path, hit by hit of material 0, slot by slot.
        std::size_t row = 0, env_entries = 0;
        std::vector<std::size_t> light_entries(lights.size(), 0);
        for (std::size_t k = 0; k < n; ++k) {
          if (tile.material[k] != 0.0) continue;
          ASSERT_LT(row, hits.size()) << where;
          EXPECT_EQ(hits.owner[row], double(k)) << where;
          const Vec3 dir(tile.dx[k], tile.dy[k], tile.dz[k]);
          const Vec3 p = camera + tile.t[k] * dir;
          Vec3 nrm = tile.inv_radius[k] != 0.0 ? (p - Vec3(tile.gx[k], tile.gy[k], tile.gz[k])) * tile.inv_radius[k]
                                               : glm::normalize(Vec3(tile.gx[k], tile.gy[k], tile.gz[k]));
          if (glm::dot(nrm, dir) > 0.0) nrm = -nrm;
          const Frame frame = with_tangent ? Frame(nrm, tangent) : Frame(nrm);
          const Vec3 o = frame.to_local(-dir), origin = p + eps * nrm;
          for (const auto& [a, b] : {std::pair{hits.tx[row], frame.t.x}, {hits.ty[row], frame.t.y}, {hits.tz[row], frame.t.z},
                                     {hits.bx[row], frame.b.x}, {hits.by[row], frame.b.y}, {hits.bz[row], frame.b.z},
                                     {hits.nx[row], frame.n.x}, {hits.ny[row], frame.n.y}, {hits.nz[row], frame.n.z},
                                     {hits.draws.ox[row], o.x}, {hits.draws.oy[row], o.y}, {hits.draws.oz[row], o.z},
                                     {hits.origin_x[row], origin.x}, {hits.origin_y[row], origin.y}, {hits.origin_z[row], origin.z},
                                     {hits.draws.u1[row], tile.u1[k]}, {hits.draws.u3[row], tile.u3[k]}})
            ASSERT_TRUE(close(a, b)) << where << " hit " << k << ": " << a << " against " << b;
          if (!constant) {
            EXPECT_EQ(hits.light_pdf[row], tile.light_pdf[k]) << where;
            EXPECT_EQ(hits.light_r[row], tile.light_r[k]) << where;
            EXPECT_TRUE(close(hits.px[row], p.x) && close(hits.pz[row], p.z)) << where;
          }
          // The environment's slot: where the light sample and the view are above the horizon.
          const Vec3 l(tile.lx[k], tile.ly[k], tile.lz[k]);
          const Vec3 il = frame.to_local(l);
          const double light_pdf = tile.light_pdf[k], light_r = tile.light_r[k];
          if (!constant && o.z > 0.0 && il.z > 0.0 && light_pdf > 0.0) {
            const std::size_t e = env_entries++;
            ASSERT_LT(e, ranges.lights_begin) << where;
            EXPECT_EQ(slots.owner[e], double(k)) << where;
            EXPECT_TRUE(close(slots.iz[e], il.z) && close(slots.rays.dx[e], l.x) && close(slots.rays.ox[e], origin.x)) << where;
            EXPECT_EQ(slots.light_pdf[e], light_pdf) << where;
            EXPECT_EQ(slots.arriving_r[e], light_r) << where;
            EXPECT_EQ(slots.arriving_g[e], 0.2) << where;
            EXPECT_EQ(slots.rays.tnear[e], eps) << where;
            EXPECT_TRUE(std::isinf(slots.rays.tfar[e])) << where;
          }
          for (std::size_t j = 0; j < lights.size(); ++j) {
            const LaneLight& light = lights[j];
            Vec3 d(light.x, light.y, light.z);
            double dist = std::numeric_limits<double>::infinity(), falloff = 1.0;
            if (!light.directional) {
              const Vec3 to = d - p;
              dist = glm::length(to), d = to / dist, falloff = 1.0 / (dist * dist), dist *= 1.0 - 1e-6;
            }
            const Vec3 i = frame.to_local(d);
            if (!(i.z > 0.0 && o.z > 0.0)) continue;
            const std::size_t e = ranges.light_begin[j] + light_entries[j]++;
            ASSERT_LT(e, j + 1 < lights.size() ? ranges.light_begin[j + 1] : ranges.brdf_begin) << where;
            EXPECT_EQ(slots.owner[e], double(k)) << where;
            EXPECT_TRUE(close(slots.iz[e], i.z) && close(slots.rays.dy[e], d.y) && close(slots.arriving_r[e], light.r * falloff)) << where;
            EXPECT_TRUE(light.directional ? std::isinf(slots.rays.tfar[e]) : close(slots.rays.tfar[e], dist)) << where;
          }
          ++row;
        }
        EXPECT_EQ(row, hits.size()) << where;
        EXPECT_EQ(env_entries, ranges.lights_begin) << where;
        for (std::size_t j = 0; j < lights.size(); ++j)
          EXPECT_EQ(ranges.light_begin[j] + light_entries[j], j + 1 < lights.size() ? ranges.light_begin[j + 1] : ranges.brdf_begin) << where;
        EXPECT_EQ(slots.size(), ranges.brdf_begin) << where;
        ASSERT_EQ(hits.draws.size(), hits.size()) << where;
        // The BRDF samples' slots: each direction found, from the hit, in the world by the hit's frame, and
        // nothing for the others.
        for (std::size_t r = 0; r < hits.size(); ++r) {
          const Vec3 i = glm::normalize(Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) + 0.1));
          hits.draws.ix[r] = i.x, hits.draws.iy[r] = i.y, hits.draws.iz[r] = i.z, hits.draws.found[r] = r % 3 == 1 ? 0.0 : 1.0;
        }
        brdf_slots(hits, Rgb(0.3, 0.2, 0.1), eps, slots, target);
        std::size_t e = ranges.brdf_begin;
        for (std::size_t r = 0; r < hits.size(); ++r) {
          if (r % 3 == 1) continue;
          ASSERT_LT(e, slots.size()) << where;
          const Vec3 i = hits.draws.i(r), t(hits.tx[r], hits.ty[r], hits.tz[r]), b(hits.bx[r], hits.by[r], hits.bz[r]);
          const Vec3 world = i.x * t + i.y * b + i.z * Vec3(hits.nx[r], hits.ny[r], hits.nz[r]);
          EXPECT_EQ(slots.owner[e], hits.owner[r]) << where;
          EXPECT_TRUE(close(slots.iz[e], i.z) && close(slots.oz[e], hits.draws.oz[r]) && close(slots.rays.dx[e], world.x) &&
                      close(slots.rays.dz[e], world.z) && close(slots.rays.oy[e], hits.origin_y[r]))
              << where << " row " << r;
          EXPECT_EQ(slots.arriving_b[e], 0.1) << where;
          EXPECT_EQ(slots.light_pdf[e], 0.0) << where;
          EXPECT_TRUE(std::isinf(slots.rays.tfar[e])) << where;
          ++e;
        }
        EXPECT_EQ(e, slots.size()) << where;
        // The values (the one-hit path's, render/integrator.cpp): an environment light sample f L cos w / p_light,
        // a light's f E cos, a BRDF sample f cos / p L w, w by the power heuristic, 1 against a density of 0
        // (a constant environment's, or a map's where it is black); none cast for a BRDF sample of density 0.
        // Densities so small that their squares underflow (1e-170) too, against 0 and against another.
        for (std::size_t q = 0; q < slots.size(); ++q) {
          slots.r[q] = 0.5 + 0.01 * double(q % 7), slots.g[q] = 0.2, slots.b[q] = 0.1;
          slots.pdf[q] = q % 6 == 5 ? 0.0 : q % 6 == 4 ? 1e-170 : 0.3 + 0.1 * double(q % 5);
          if (q >= ranges.brdf_begin && !constant) slots.light_pdf[q] = q % 4 == 0 ? 0.0 : q % 4 == 1 ? 3e-170 : 0.2;  // a map looked up
        }
        shadow_values(slots, ranges, target);
        for (std::size_t q = 0; q < slots.size(); ++q) {
          const double f = slots.r[q], arriving = slots.arriving_r[q], cos_i = slots.iz[q], pdf = slots.pdf[q], light_pdf = slots.light_pdf[q];
          double want = f * arriving * cos_i;  // a light
          // w(p, q) / p = p / (p^2 + q^2) in long double, whose exponent holds the squares of 1e-170.
          const auto weight_over = [](long double own, long double other) { return double(own / (own * own + other * other)); };
          if (q < ranges.lights_begin) want = f * arriving * cos_i * weight_over(light_pdf, pdf);
          if (q >= ranges.brdf_begin) {
            EXPECT_EQ(slots.casts[q], pdf > 0.0 ? 1.0 : 0.0) << where << " entry " << q;
            if (!(pdf > 0.0)) continue;
            want = f * cos_i * arriving * weight_over(pdf, light_pdf);
            if (light_pdf == 0.0) {
              EXPECT_TRUE(close(want, f * cos_i / pdf * arriving)) << where;  // weighs 1
            }
          }
          ASSERT_TRUE(std::isfinite(slots.value_r[q])) << where << " entry " << q;
          EXPECT_TRUE(close(slots.value_r[q], want)) << where << " entry " << q << ": " << slots.value_r[q] << " against " << want;
        }
      }
  }
}

TEST(Wavefront, TakeHitsLooksUpEachPixelsObject) {
  // Objects: a sphere shaded in lanes, a mesh shaded in lanes, a sphere shaded one hit at a time. Runs of
  // one object (the one-lookup vectors), mixed vectors and misses; every target; every entry exactly.
  LaneObjects objects;
  objects.material = {0.0, 1.0, -1.0};
  objects.cx = {0.5, 0.0, -2.0}, objects.cy = {1.0, 0.0, 3.0}, objects.cz = {-1.0, 0.0, 0.25};
  objects.inv_radius = {2.0, 0.0, 0.125};
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Rgb background(0.3, 0.2, 0.1);
  for (const std::size_t n : {1u, 5u, 16u, 37u, 256u})
    for (const SimdTarget target : kSimdTargets) {
      RayHits hits;
      hits.resize_to(n);
      for (std::size_t k = 0; k < hits.padded_size(); ++k) {
        const int run = int(k / 8) % 5;  // 8 alike (objects 0, 1, 2, a miss), then mixed
        hits.object[k] = run == 4 ? double(int(u(rng) * 4.0) - 1) : run == 3 ? -1.0 : double(run);
        hits.t[k] = hits.object[k] >= 0.0 ? 1.0 + u(rng) : std::numeric_limits<double>::infinity();
        hits.ngx[k] = hits.object[k] == 1.0 ? u(rng) : 0.0, hits.ngy[k] = hits.object[k] == 1.0 ? 1.0 : 0.0, hits.ngz[k] = hits.object[k] == 1.0 ? -0.5 : 0.0;
      }
      TileHits tile;
      tile.resize_to(n);
      std::vector<double> alpha(hits.padded_size()), radiance[3];
      for (auto& c : radiance) c.assign(hits.padded_size(), -7.0);
      double* out[3] = {radiance[0].data(), radiance[1].data(), radiance[2].data()};
      take_hits(hits, objects, background, tile, alpha.data(), out, target);
      const std::string where = std::to_string(n) + " " + simd_target_name(target);
      for (std::size_t k = 0; k < hits.padded_size(); ++k) {
        const double o = hits.object[k];
        const bool hit = o >= 0.0;
        const std::size_t i = hit ? std::size_t(o) : 0;
        EXPECT_EQ(tile.material[k], hit ? objects.material[i] : -1.0) << where << " " << k;
        EXPECT_EQ(alpha[k], hit ? 1.0 : 0.0) << where << " " << k;
        for (int c = 0; c < 3; ++c) EXPECT_EQ(radiance[c][k], hit ? 0.0 : background[c]) << where << " " << k << " channel " << c;
        if (!hit) continue;
        EXPECT_EQ(tile.t[k], hits.t[k]) << where << " " << k;
        EXPECT_EQ(tile.inv_radius[k], objects.inv_radius[i]) << where << " " << k;
        EXPECT_EQ(tile.gx[k], i == 1 ? hits.ngx[k] : objects.cx[i]) << where << " " << k;
        EXPECT_EQ(tile.gy[k], i == 1 ? hits.ngy[k] : objects.cy[i]) << where << " " << k;
        EXPECT_EQ(tile.gz[k], i == 1 ? hits.ngz[k] : objects.cz[i]) << where << " " << k;
      }
    }
}

TEST(Wavefront, SamplesAddToTheSumsAsOneAtATime) {
  // Lengths around the lane counts, radiance with a NaN or an infinity in one channel (the pixel adds
  // nothing but its alpha), every target; the sums exactly.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const std::size_t n : {1u, 3u, 4u, 7u, 8u, 9u, 17u, 256u})
    for (const SimdTarget target : kSimdTargets) {
      std::vector<double> radiance[3], alpha(n), sum[4], want[4];
      for (auto& c : radiance) c.resize(n);
      for (int c = 0; c < 4; ++c) sum[c].resize(n);
      for (std::size_t k = 0; k < n; ++k) {
        for (auto& c : radiance) c[k] = u(rng);
        if (k % 5 == 1) radiance[k % 3][k] = k % 2 ? std::numeric_limits<double>::quiet_NaN() : std::numeric_limits<double>::infinity();
        alpha[k] = double(k % 2);
        for (int c = 0; c < 4; ++c) sum[c][k] = u(rng);
      }
      for (int c = 0; c < 4; ++c) want[c] = sum[c];
      for (std::size_t k = 0; k < n; ++k) {
        const bool finite = std::isfinite(radiance[0][k]) && std::isfinite(radiance[1][k]) && std::isfinite(radiance[2][k]);
        for (int c = 0; c < 3; ++c) want[c][k] += finite ? radiance[c][k] : 0.0;
        want[3][k] += alpha[k];
      }
      const double* in[3] = {radiance[0].data(), radiance[1].data(), radiance[2].data()};
      double* out[4] = {sum[0].data(), sum[1].data(), sum[2].data(), sum[3].data()};
      add_samples(in, alpha.data(), out, n, target);
      for (int c = 0; c < 4; ++c) EXPECT_EQ(sum[c], want[c]) << n << " " << simd_target_name(target) << " channel " << c;
    }
}

TEST(Camera, SamplesInSimdLanesEqualOneAtATime) {
  // The numbers exactly (integer arithmetic, and 32 bits to a double), the directions to rounding; pixels
  // of a wide image (large keys), seeds that set the high bits, sample indices past 2^24 (shifted by 40),
  // batches of every length modulo the lane count; every target (the best one: AVX-512's whole 64-bit
  // multiplications where the CPU has it; AVX2's from 32-bit halves; the baseline).
  PinholeCamera camera;
  camera.position = Vec3(0.0, 0.6, 4.0);
  camera.forward = glm::normalize(-camera.position);
  camera.right = glm::normalize(glm::cross(camera.forward, Vec3(0.0, 1.0, 0.0)));
  camera.up = glm::cross(camera.right, camera.forward);
  camera.tan_half = std::tan(0.5 * 30.0 * kPi / 180.0), camera.aspect = 16000.0 / 9000.0;
  camera.to_sx = 2.0 / 16000.0, camera.to_sy = 2.0 / 9000.0;
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> px(0, 15999), py(0, 8999);
  for (const SimdTarget target : kSimdTargets)
    for (std::size_t n : {1, 3, 4, 15, 16, 17, 61})
      for (const auto& [seed, s] : {std::pair<std::uint64_t, int>{1, 0}, {0xFFFFFFFFFFFFull, 63}, {7, (1 << 24) + 5}}) {
        CameraSampleBatch batch;
        std::vector<std::pair<int, int>> pixels;
        for (std::size_t k = 0; k < n; ++k) {
          pixels.emplace_back(k == 0 ? 0 : px(rng), k == 0 ? 0 : py(rng));
          batch.push(pixels.back().first, pixels.back().second);
        }
        camera_sample_batch(camera, seed, s, batch, target);
        // Only the numbers a constant environment reads (the camera's and the BRDF sample's), into a batch
        // whose columns hold something else: those, the same; the rest, not written.
        CameraSampleBatch some = batch;
        for (auto& column : some.u) std::fill(column.begin(), column.end(), -1.0);
        const unsigned read = sample_numbers_read(true, false);
        camera_sample_batch(camera, seed, s, some, target, read);
        for (std::size_t k = 0; k < n; ++k) {
          const auto [x, y] = pixels[k];
          const std::uint64_t start = SampleSequence::start(seed, SampleSequence::pixel_key(x, y), s);
          double u[kSampleNumbers];
          for (int j = 0; j < kSampleNumbers; ++j) {
            u[j] = SampleSequence::number(start, j);
            ASSERT_EQ(batch.u[j][k], u[j]) << "number " << j << " of pixel (" << x << ", " << y << ")";
            ASSERT_EQ(some.u[j][k], read >> j & 1u ? u[j] : -1.0) << "number " << j << " of pixel (" << x << ", " << y << ")";
            ASSERT_TRUE(u[j] >= 0.0 && u[j] < 1.0);
          }
          const Vec3 want = camera.direction(x, y, u[0], u[1]), got = batch.d(k);
          EXPECT_NEAR(got.x, want.x, 1e-15) << k;
          EXPECT_NEAR(got.y, want.y, 1e-15) << k;
          EXPECT_NEAR(got.z, want.z, 1e-15) << k;
        }
      }
}

}  // namespace
}  // namespace facetfit
