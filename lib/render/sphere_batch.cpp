// Compiled once per SIMD target by Highway's foreach_target (this file includes itself), as
// render/ggx_batch.cpp.
#include "render/simd_targets.h"  // before any of Highway's headers
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "render/sphere_batch.cpp"
#include <hwy/foreach_target.h>  // before highway.h

#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

#include <algorithm>
#include <cstdint>
#include <limits>

#include "render/lanes-inl.h"
#include "render/sphere_batch.h"

HWY_BEFORE_NAMESPACE();
namespace facetfit {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace {

using lanes::D;
using lanes::V;

struct RayV {
  V ox, oy, oz, dx, dy, dz, tnear, tfar;
};

HWY_INLINE RayV ray_at(D d, const RayBatch& rays, std::size_t k) {
  return {hn::LoadU(d, rays.ox.data() + k), hn::LoadU(d, rays.oy.data() + k), hn::LoadU(d, rays.oz.data() + k),
          hn::LoadU(d, rays.dx.data() + k), hn::LoadU(d, rays.dy.data() + k), hn::LoadU(d, rays.dz.data() + k),
          hn::LoadU(d, rays.tnear.data() + k), hn::LoadU(d, rays.tfar.data() + k)};
}

// intersect_sphere (render/tracer.cpp) in lanes: the nearest root in (tnear, tfar) or infinity. Every
// operation as the scalar code orders it (glm's dot sums x, y, then z), the divisions by AVX-512's refined
// reciprocal (render/lanes-inl.h) on that target.
HWY_INLINE V intersect(D d, V cx, V cy, V cz, V radius, const RayV& r, V tfar) {
  const V zero = hn::Zero(d), inf = hn::Set(d, std::numeric_limits<double>::infinity());
  const V fx = r.ox - cx, fy = r.oy - cy, fz = r.oz - cz;
  const V a = r.dx * r.dx + r.dy * r.dy + r.dz * r.dz;
  const V b = hn::Neg(fx * r.dx + fy * r.dy + fz * r.dz);
  const V r2 = radius * radius;
  const V c = (fx * fx + fy * fy + fz * fz) - r2;
  const auto away = hn::And(c > zero, hn::And(b <= zero, r.tnear >= zero));
  // Every shadow ray leaving a sphere's lit side ends here, without the divisions and the square root.
  if (hn::AllTrue(d, away)) return inf;
  const V inv_a = lanes::reciprocal(d, a), s = b * inv_a;
  const V nx = fx + s * r.dx, ny = fy + s * r.dy, nz = fz + s * r.dz;
  const V chord2 = r2 - (nx * nx + ny * ny + nz * nz);
  const auto meets = hn::AndNot(away, chord2 >= zero);
  // Camera rays past a sphere's outline miss it together: no square root, no second division.
  if (hn::AllFalse(d, meets)) return inf;
  const V q = b + hn::CopySign(hn::Sqrt(hn::IfThenElseZero(meets, a * chord2)), b);
  const V t0 = q * inv_a, t1 = hn::IfThenElse(q != zero, lanes::divide(d, c, hn::IfThenElse(q != zero, q, hn::Set(d, 1.0))), t0);
  const auto swap = t0 > t1;
  const V lo = hn::IfThenElse(swap, t1, t0), hi = hn::IfThenElse(swap, t0, t1);
  const V t = hn::IfThenElse(hn::And(lo > r.tnear, lo < tfar), lo, hn::IfThenElse(hn::And(hi > r.tnear, hi < tfar), hi, inf));
  return hn::IfThenElse(meets, t, inf);
}

}  // namespace

void BlockedBySpheres(const SphereSet& spheres, const RayBatch& rays, std::vector<char>& blocked) {
  const D d;
  const std::size_t lanes = hn::Lanes(d), n = rays.size();
  const V inf = hn::Set(d, std::numeric_limits<double>::infinity());
  for (std::size_t k = 0; k < n; k += lanes) {
    const RayV r = ray_at(d, rays, k);
    auto hit = hn::FirstN(d, 0);
    for (std::size_t s = 0; s < spheres.size(); ++s) {
      const V t = intersect(d, hn::Set(d, spheres.cx[s]), hn::Set(d, spheres.cy[s]), hn::Set(d, spheres.cz[s]), hn::Set(d, spheres.radius[s]),
                            r, r.tfar);
      hit = hn::Or(hit, t < inf);
    }
    std::uint8_t bits[8] = {};
    hn::StoreMaskBits(d, hit, bits);
    const std::size_t count = std::min(lanes, n - k);
    for (std::size_t j = 0; j < count; ++j)
      if ((bits[j / 8] >> (j % 8)) & 1) blocked[k + j] = 1;
  }
}

// The nearest sphere of the rays ray_at(d, k) for k < n, as NearestSpheres below.
template <class RayAt>
HWY_INLINE void nearest(const SphereSet& spheres, std::size_t n, const RayAt& ray_at, std::vector<double>& t, std::vector<double>& id) {
  const D d;
  const std::size_t lanes = hn::Lanes(d);
  if (t.size() < n) t.resize(n);
  if (id.size() < n) id.resize(n);
  const V inf = hn::Set(d, std::numeric_limits<double>::infinity());
  for (std::size_t k = 0; k < n; k += lanes) {
    const RayV r = ray_at(d, k);
    V tfar = r.tfar, best = inf, which = hn::Set(d, -1.0);
    for (std::size_t s = 0; s < spheres.size(); ++s) {
      const V ts = intersect(d, hn::Set(d, spheres.cx[s]), hn::Set(d, spheres.cy[s]), hn::Set(d, spheres.cz[s]), hn::Set(d, spheres.radius[s]),
                             r, tfar);
      const auto nearer = ts < tfar;
      tfar = hn::IfThenElse(nearer, ts, tfar), best = hn::IfThenElse(nearer, ts, best);
      which = hn::IfThenElse(nearer, hn::Set(d, spheres.id[s]), which);
    }
    hn::StoreU(best, d, t.data() + k);
    hn::StoreU(which, d, id.data() + k);
  }
}

void NearestSpheres(const SphereSet& spheres, const RayBatch& rays, std::vector<double>& t, std::vector<double>& id) {
  nearest(spheres, rays.padded_size(), [&rays](D d, std::size_t k) { return ray_at(d, rays, k); }, t, id);
}

void NearestSpheresFromPoint(const SphereSet& spheres, const RaysFromPoint& rays, std::vector<double>& t, std::vector<double>& id) {
  const D d;
  const V ox = hn::Set(d, rays.origin.x), oy = hn::Set(d, rays.origin.y), oz = hn::Set(d, rays.origin.z);
  const V tnear = hn::Zero(d), tfar = hn::Set(d, std::numeric_limits<double>::infinity());
  nearest(spheres, rays.padded_size(), [&](D, std::size_t k) {
    return RayV{ox, oy, oz, hn::LoadU(d, rays.dx + k), hn::LoadU(d, rays.dy + k), hn::LoadU(d, rays.dz + k), tnear, tfar};
  }, t, id);
}

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace facetfit
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "render/simd_dispatch.h"
namespace facetfit {

void blocked_by_spheres(const SphereSet& spheres, const RayBatch& rays, std::vector<char>& blocked, SimdTarget target) {
  FACETFIT_DISPATCH(target, BlockedBySpheres, spheres, rays, blocked);
}

void nearest_spheres(const SphereSet& spheres, const RayBatch& rays, std::vector<double>& t, std::vector<double>& id, SimdTarget target) {
  FACETFIT_DISPATCH(target, NearestSpheres, spheres, rays, t, id);
}

void nearest_spheres(const SphereSet& spheres, const RaysFromPoint& rays, std::vector<double>& t, std::vector<double>& id, SimdTarget target) {
  FACETFIT_DISPATCH(target, NearestSpheresFromPoint, spheres, rays, t, id);
}

}  // namespace facetfit
#endif
