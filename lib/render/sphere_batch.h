// Rays in columns, and the scene's spheres tested against many of them at once in SIMD lanes (Google
// Highway, as render/ggx_batch.h): intersect_sphere (render/tracer.h) in every lane, with the same
// operations in the same order, so that each answer equals the one-ray query's to rounding (the compiler
// fuses multiply-adds in the AVX2 code). Many at once because, one ray at a time, the closed form and the
// rays' copies would be a large share of a sphere's render (docs/render-speed.md).
#pragma once

#include <cstddef>
#include <vector>

#include "core/vec.h"
#include "render/shading_batch.h"
#include "render/simd_targets.h"

namespace facetfit {

// Rays from origin (ox, oy, oz) along (dx, dy, dz), for t in (tnear, tfar).
struct RayBatch : Columns {
  std::vector<double> ox, oy, oz, dx, dy, dz, tnear, tfar;
  std::size_t push(const Vec3& origin, const Vec3& d, double t0, double t1) {
    const std::size_t k = next([this](std::size_t n) { grow(n); });
    ox[k] = origin.x, oy[k] = origin.y, oz[k] = origin.z, dx[k] = d.x, dy[k] = d.y, dz[k] = d.z, tnear[k] = t0, tfar[k] = t1;
    return k;
  }
  // Room for n rays written in place by SIMD kernels (whole vectors); size() stays.
  void reserve(std::size_t n) {
    ensure(n, [this](std::size_t m) { grow(m); });
  }
  void set_size(std::size_t n) { Columns::set_size(n); }

 private:
  void grow(std::size_t n) {
    resize({&ox, &oy, &oz, &dx, &dy, &tnear, &tfar}, n, 0.0);
    resize({&dz}, n, 1.0);
  }
};

// The spheres of a scene, in columns, and the id nearest_spheres() reports for each (the tracer's: the
// scene's object index).
struct SphereSet {
  std::vector<double> cx, cy, cz, radius, id;
  std::size_t size() const { return radius.size(); }
};

// Per ray of the batch (its size() rays), whether a sphere meets it in (tnear, tfar): blocked[k] is set to 1
// where one does and left as it is otherwise.
void blocked_by_spheres(const SphereSet& spheres, const RayBatch& rays, std::vector<char>& blocked, SimdTarget target = SimdTarget::best);

// Per ray, the nearest sphere in (tnear, tfar): t (infinity where none) and its id (-1 where none), for
// the batch's padded_size() rays (columns shorter than that grow).
void nearest_spheres(const SphereSet& spheres, const RayBatch& rays, std::vector<double>& t, std::vector<double>& id,
                     SimdTarget target = SimdTarget::best);

// Rays from one point (a camera's) along directions (dx, dy, dz), for t in (0, infinity): `size` rays, in
// columns the caller owns with room for size rounded up to Columns::kPadding. A camera's rays need no
// columns of origins and bounds, and their shared terms are computed once per sphere.
struct RaysFromPoint {
  Vec3 origin;
  const double *dx, *dy, *dz;
  std::size_t size;
  std::size_t padded_size() const { return Columns::padded(size); }
};
void nearest_spheres(const SphereSet& spheres, const RaysFromPoint& rays, std::vector<double>& t, std::vector<double>& id,
                     SimdTarget target = SimdTarget::best);

}  // namespace facetfit
