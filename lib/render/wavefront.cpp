// Compiled once per SIMD target by Highway's foreach_target (this file includes itself), as
// render/ggx_batch.cpp.
#include "render/simd_targets.h"  // before any of Highway's headers
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "render/wavefront.cpp"
#include <hwy/foreach_target.h>  // before highway.h

#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

#include <cstdint>
#include <limits>
#include <stdexcept>

#include "render/lanes-inl.h"
#include "render/wavefront.h"

HWY_BEFORE_NAMESPACE();
namespace facetfit {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace {

using lanes::D;
using lanes::V;
using M = hn::Mask<D>;

struct Vec3V {
  V x, y, z;
};

// A hit's shading frame, as Frame (core/frame.h) holds it.
struct FrameV {
  Vec3V t, b, n;
  Vec3V to_local(const Vec3V& v) const {
    return {v.x * t.x + v.y * t.y + v.z * t.z, v.x * b.x + v.y * b.y + v.z * b.z, v.x * n.x + v.y * n.y + v.z * n.z};
  }
  Vec3V to_world(const Vec3V& v) const {
    return {v.x * t.x + v.y * b.x + v.z * n.x, v.x * t.y + v.y * b.y + v.z * n.y, v.x * t.z + v.y * b.z + v.z * n.z};
  }
};

V load(D d, const std::vector<double>& column, std::size_t k) { return hn::LoadU(d, column.data() + k); }
V load(D d, const double* column, std::size_t k) { return hn::LoadU(d, column + k); }

FrameV frame_at(D d, const HitBatch& h, std::size_t k) {
  return {{load(d, h.tx, k), load(d, h.ty, k), load(d, h.tz, k)},
          {load(d, h.bx, k), load(d, h.by, k), load(d, h.bz, k)},
          {load(d, h.nx, k), load(d, h.ny, k), load(d, h.nz, k)}};
}

// One slot per lane, before compaction.
struct Entry {
  Vec3V o, i, d;
  V with_pdf, tfar, arriving_r, arriving_g, arriving_b, light_pdf, owner;
};
// Stores vectors with the lanes of a mask moved to the front, from position `at` of a column: a whole
// vector is written, the columns have room past their entries.
#if HWY_TARGET == HWY_AVX3
// AVX-512 compresses in a register (vcompresspd to memory is slower), then stores the whole vector.
struct ToFront {
  M mask;
  std::size_t at;
  HWY_INLINE void operator()(D, V v, std::vector<double>& column) const {
    _mm512_storeu_pd(column.data() + at, _mm512_maskz_compress_pd(mask.raw, v.raw));
  }
};
HWY_INLINE ToFront to_front(D, M m, std::size_t at) { return {m, at}; }
#else
// Elsewhere vectors hold at most 4 doubles (render/simd_targets.h): the lanes of mask bits m in order,
// from a table of our own (Highway's CompressStore copies a 256-byte table onto the stack at every call,
// hwy 1.0.3).
static_assert(hn::MaxLanes(D()) <= 4, "the compression table holds 4 lanes");
struct CompressTable {
  std::int64_t index[16][4];
};
constexpr CompressTable kCompress = [] {
  CompressTable t{};
  for (int m = 0; m < 16; ++m) {
    int at = 0;
    for (int lane = 0; lane < 4; ++lane)
      if (m & (1 << lane)) t.index[m][at++] = lane;
  }
  return t;
}();
// Where every lane stays (most vectors inside an object), a plain store: Zen's cross-lane permutation costs
// three operations a column.
struct ToFront {
  decltype(hn::SetTableIndices(D(), static_cast<const std::int64_t*>(nullptr))) index;
  std::size_t at;
  bool whole;
  HWY_INLINE void operator()(D d, V v, std::vector<double>& column) const {
    hn::StoreU(whole ? v : hn::TableLookupLanes(v, index), d, column.data() + at);
  }
};
HWY_INLINE ToFront to_front(D d, M m, std::size_t at) {
  std::uint8_t bits[8] = {};
  hn::StoreMaskBits(d, m, bits);
  const int lanes = bits[0] & 15;
  return {hn::SetTableIndices(d, kCompress.index[lanes]), at, lanes == (1 << hn::Lanes(d)) - 1};
}
#endif

// Appends the lanes of `m` as entries of `out` from position `at`: one evaluation (o, i, with_pdf) and
// its shadow ray (origin, direction, tnear, length), the arriving radiance, the environment density and the
// pixel it lights (the hit's owner). Returns the count.
HWY_INLINE std::size_t append(D d, M m, const Entry& e, const Vec3V& origin, V tnear, ShadowBatch& out, std::size_t at) {
  const ToFront put = to_front(d, m, at);
  put(d, e.o.x, out.ox), put(d, e.o.y, out.oy), put(d, e.o.z, out.oz);
  put(d, e.i.x, out.ix), put(d, e.i.y, out.iy), put(d, e.i.z, out.iz), put(d, e.with_pdf, out.with_pdf);
  put(d, origin.x, out.rays.ox), put(d, origin.y, out.rays.oy), put(d, origin.z, out.rays.oz);
  put(d, e.d.x, out.rays.dx), put(d, e.d.y, out.rays.dy), put(d, e.d.z, out.rays.dz), put(d, tnear, out.rays.tnear);
  put(d, e.tfar, out.rays.tfar);
  put(d, e.arriving_r, out.arriving_r), put(d, e.arriving_g, out.arriving_g), put(d, e.arriving_b, out.arriving_b);
  put(d, e.light_pdf, out.light_pdf), put(d, e.owner, out.owner);
  return hn::CountTrue(d, m);
}

// The lanes from k on that hold one of the batch's `count` entries (the padding past them may repeat an
// earlier tile's).
HWY_INLINE M real(D d, std::size_t k, std::size_t count) { return hn::Iota(d, double(k)) < hn::Set(d, double(count)); }

HWY_INLINE V dot(const Vec3V& a, const Vec3V& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// glm::normalize: v times the reciprocal of its length.
HWY_INLINE Vec3V normalize(D d, const Vec3V& v) {
  const V inv = lanes::inverse_sqrt(d, dot(v, v));
  return {v.x * inv, v.y * inv, v.z * inv};
}

}  // namespace

void PlaceHits(const TileHits& tile, const Vec3& camera, double eps, double material, const Vec3* tangent, bool positions, HitBatch& out) {
  const D d;
  const std::size_t n = tile.padded_size(), lanes = hn::Lanes(d);
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), this_material = hn::Set(d, material), epsilon = hn::Set(d, eps);
  out.clear();
  out.reserve(tile.size() + lanes);
  out.positions = positions;
  out.light_sampled = tile.light_sampled;
  std::size_t size = 0;
  for (std::size_t k = 0; k < n; k += lanes) {
    const M mine = hn::And(real(d, k, tile.size()), load(d, tile.material, k) == this_material);
    if (hn::AllFalse(d, mine)) continue;
    const V t = load(d, tile.t, k);
    const Vec3V dir{load(d, tile.dx, k), load(d, tile.dy, k), load(d, tile.dz, k)};
    const Vec3V p{hn::Set(d, camera.x) + t * dir.x, hn::Set(d, camera.y) + t * dir.y, hn::Set(d, camera.z) + t * dir.z};
    const Vec3V g{load(d, tile.gx, k), load(d, tile.gy, k), load(d, tile.gz, k)};
    const V inv_radius = load(d, tile.inv_radius, k);
    Vec3V nrm{(p.x - g.x) * inv_radius, (p.y - g.y) * inv_radius, (p.z - g.z) * inv_radius};
    const M triangle = hn::And(mine, inv_radius == zero);
    if (!hn::AllFalse(d, triangle)) {
      const Vec3V ng = normalize(d, g);
      nrm = {hn::IfThenElse(triangle, ng.x, nrm.x), hn::IfThenElse(triangle, ng.y, nrm.y), hn::IfThenElse(triangle, ng.z, nrm.z)};
    }
    // Shade the side the camera sees.
    const M back = dot(nrm, dir) > zero;
    nrm = {hn::IfThenElse(back, hn::Neg(nrm.x), nrm.x), hn::IfThenElse(back, hn::Neg(nrm.y), nrm.y), hn::IfThenElse(back, hn::Neg(nrm.z), nrm.z)};
    // Frame(n) of core/frame.h (Duff et al. 2017).
    const V sign = hn::CopySign(one, nrm.z), a = hn::Neg(lanes::reciprocal(d, sign + nrm.z)), c = nrm.x * nrm.y * a;
    FrameV frame{{one + sign * nrm.x * nrm.x * a, sign * c, hn::Neg(sign * nrm.x)}, {c, sign + nrm.y * nrm.y * a, hn::Neg(nrm.y)}, nrm};
    if (tangent) {
      // Frame(n, along): the tangent's projection on the surface where it does not vanish.
      const Vec3V along{hn::Set(d, tangent->x), hn::Set(d, tangent->y), hn::Set(d, tangent->z)};
      const V along_n = dot(along, nrm);
      const Vec3V projected{along.x - along_n * nrm.x, along.y - along_n * nrm.y, along.z - along_n * nrm.z};
      const V len = hn::Sqrt(dot(projected, projected));
      const M turns = len > hn::Set(d, 1e-9);
      const V safe = hn::IfThenElse(turns, len, one);
      const V inv_len = lanes::reciprocal(d, safe);
      const Vec3V t_axis{projected.x * inv_len, projected.y * inv_len, projected.z * inv_len};
      const Vec3V b_axis{nrm.y * t_axis.z - nrm.z * t_axis.y, nrm.z * t_axis.x - nrm.x * t_axis.z, nrm.x * t_axis.y - nrm.y * t_axis.x};
      frame.t = {hn::IfThenElse(turns, t_axis.x, frame.t.x), hn::IfThenElse(turns, t_axis.y, frame.t.y), hn::IfThenElse(turns, t_axis.z, frame.t.z)};
      frame.b = {hn::IfThenElse(turns, b_axis.x, frame.b.x), hn::IfThenElse(turns, b_axis.y, frame.b.y), hn::IfThenElse(turns, b_axis.z, frame.b.z)};
    }
    const Vec3V o = frame.to_local({hn::Neg(dir.x), hn::Neg(dir.y), hn::Neg(dir.z)});
    const ToFront put = to_front(d, mine, size);
    put(d, frame.t.x, out.tx), put(d, frame.t.y, out.ty), put(d, frame.t.z, out.tz);
    put(d, frame.b.x, out.bx), put(d, frame.b.y, out.by), put(d, frame.b.z, out.bz);
    put(d, nrm.x, out.nx), put(d, nrm.y, out.ny), put(d, nrm.z, out.nz);
    put(d, o.x, out.draws.ox), put(d, o.y, out.draws.oy), put(d, o.z, out.draws.oz);
    if (positions) put(d, p.x, out.px), put(d, p.y, out.py), put(d, p.z, out.pz);
    put(d, p.x + epsilon * nrm.x, out.origin_x), put(d, p.y + epsilon * nrm.y, out.origin_y), put(d, p.z + epsilon * nrm.z, out.origin_z);
    if (tile.light_sampled) {
      put(d, load(d, tile.lx, k), out.lx), put(d, load(d, tile.ly, k), out.ly), put(d, load(d, tile.lz, k), out.lz);
      put(d, load(d, tile.light_pdf, k), out.light_pdf);
      put(d, load(d, tile.light_r, k), out.light_r), put(d, load(d, tile.light_g, k), out.light_g), put(d, load(d, tile.light_b, k), out.light_b);
    }
    put(d, load(d, tile.u1, k), out.draws.u1), put(d, load(d, tile.u2, k), out.draws.u2), put(d, load(d, tile.u3, k), out.draws.u3);
    put(d, hn::Iota(d, double(k)), out.owner);
    size += hn::CountTrue(d, mine);
  }
  out.set_size(size);
}

void TakeHits(const RayHits& hits, const LaneObjects& objects, const Rgb& background, TileHits& tile, double* alpha,
              double* const radiance[3]) {
  const D d;
  const std::size_t n = hits.padded_size(), lanes = hn::Lanes(d);
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), none = hn::Set(d, -1.0);
  const V seen[3] = {hn::Set(d, background.r), hn::Set(d, background.g), hn::Set(d, background.b)};
  for (std::size_t k = 0; k < n; k += lanes) {
    const V object = load(d, hits.object, k);
    const M hit = object >= zero;
    V material = none, inv_radius = zero, cx = zero, cy = zero, cz = zero;
    if (!hn::AllFalse(d, hit)) {
      const V first = hn::MaxOfLanes(d, object);  // an object some lane hit
      if (hn::AllTrue(d, hn::Or(hn::Not(hit), object == first))) {
        const std::size_t o = std::size_t(hn::GetLane(first));
        material = hn::Set(d, objects.material[o]), inv_radius = hn::Set(d, objects.inv_radius[o]);
        cx = hn::Set(d, objects.cx[o]), cy = hn::Set(d, objects.cy[o]), cz = hn::Set(d, objects.cz[o]);
      } else {
        HWY_ALIGN double which[hn::MaxLanes(D())], m[hn::MaxLanes(D())], r[hn::MaxLanes(D())], x[hn::MaxLanes(D())],
            y[hn::MaxLanes(D())], z[hn::MaxLanes(D())];
        hn::Store(object, d, which);
        for (std::size_t j = 0; j < lanes; ++j) {
          const std::size_t o = which[j] >= 0.0 ? std::size_t(which[j]) : 0;  // a miss reads object 0, masked below
          m[j] = objects.material[o], r[j] = objects.inv_radius[o], x[j] = objects.cx[o], y[j] = objects.cy[o], z[j] = objects.cz[o];
        }
        material = hn::Load(d, m), inv_radius = hn::Load(d, r), cx = hn::Load(d, x), cy = hn::Load(d, y), cz = hn::Load(d, z);
      }
    }
    const M sphere = inv_radius != zero;
    hn::StoreU(load(d, hits.t, k), d, tile.t.data() + k);
    hn::StoreU(hn::IfThenElse(hit, material, none), d, tile.material.data() + k);
    hn::StoreU(hn::IfThenElseZero(hit, inv_radius), d, tile.inv_radius.data() + k);
    hn::StoreU(hn::IfThenElse(sphere, cx, load(d, hits.ngx, k)), d, tile.gx.data() + k);
    hn::StoreU(hn::IfThenElse(sphere, cy, load(d, hits.ngy, k)), d, tile.gy.data() + k);
    hn::StoreU(hn::IfThenElse(sphere, cz, load(d, hits.ngz, k)), d, tile.gz.data() + k);
    hn::StoreU(hn::IfThenElseZero(hit, one), d, alpha + k);
    for (int c = 0; c < 3; ++c) hn::StoreU(hn::IfThenZeroElse(hit, seen[c]), d, radiance[c] + k);
  }
}

HWY_INLINE Vec3V view_at(D d, const HitBatch& h, std::size_t k) {
  return {load(d, h.draws.ox, k), load(d, h.draws.oy, k), load(d, h.draws.oz, k)};
}

HWY_INLINE Vec3V origin_at(D d, const HitBatch& h, std::size_t k) {
  return {load(d, h.origin_x, k), load(d, h.origin_y, k), load(d, h.origin_z, k)};
}

void LightSlots(const HitBatch& hits, const std::vector<LaneLight>& lights, double tnear, ShadowBatch& out,
                SlotRanges& ranges) {
  const D d;
  const std::size_t n = hits.padded_size(), lanes = hn::Lanes(d);
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), infinity = hn::Set(d, std::numeric_limits<double>::infinity());
  // Every slot of every hit, and a vector's worth past the last for the stores.
  out.clear();
  out.reserve(n * (1 + lights.size()) + lanes);
  std::size_t size = 0;
  if (hits.light_sampled) {
    for (std::size_t k = 0; k < n; k += lanes) {
      const FrameV frame = frame_at(d, hits, k);
      const Vec3V o = view_at(d, hits, k);
      const Vec3V l{load(d, hits.lx, k), load(d, hits.ly, k), load(d, hits.lz, k)};
      const V pdf = load(d, hits.light_pdf, k);
      const Vec3V il = frame.to_local(l);
      const M lit = hn::And(real(d, k, hits.size()), hn::And(o.z > zero, hn::And(il.z > zero, pdf > zero)));
      size += append(d, lit,
                     {o, il, l, one, infinity, load(d, hits.light_r, k), load(d, hits.light_g, k), load(d, hits.light_b, k), pdf,
                      load(d, hits.owner, k)},
                     origin_at(d, hits, k), hn::Set(d, tnear), out, size);
    }
  }
  ranges.lights_begin = size;
  ranges.light_begin.clear();
  for (const LaneLight& light : lights) {
    ranges.light_begin.push_back(size);
    const V vx = hn::Set(d, light.x), vy = hn::Set(d, light.y), vz = hn::Set(d, light.z);
    const V r = hn::Set(d, light.r), g = hn::Set(d, light.g), b = hn::Set(d, light.b);
    for (std::size_t k = 0; k < n; k += lanes) {
      const FrameV frame = frame_at(d, hits, k);
      const Vec3V o = view_at(d, hits, k);
      Entry e{o, {}, {vx, vy, vz}, zero, infinity, r, g, b, zero, load(d, hits.owner, k)};
      if (!light.directional) {
        // Toward the point from the hit, its irradiance falling as the squared distance, the ray stopping
        // just short of it.
        const V to_x = vx - load(d, hits.px, k), to_y = vy - load(d, hits.py, k), to_z = vz - load(d, hits.pz, k);
        const V dist2 = to_x * to_x + to_y * to_y + to_z * to_z, inv_dist = lanes::inverse_sqrt(d, dist2), inv2 = inv_dist * inv_dist;
        const V dist = dist2 * inv_dist;
        e.d = {to_x * inv_dist, to_y * inv_dist, to_z * inv_dist};
        e.arriving_r = r * inv2, e.arriving_g = g * inv2, e.arriving_b = b * inv2;
        e.tfar = dist * hn::Set(d, 1.0 - 1e-6);
      }
      e.i = frame.to_local(e.d);
      size += append(d, hn::And(real(d, k, hits.size()), hn::And(e.i.z > zero, o.z > zero)), e, origin_at(d, hits, k), hn::Set(d, tnear), out,
                     size);
    }
  }
  ranges.brdf_begin = size;
  out.set_size(size);
}

void BrdfSlots(const HitBatch& hits, const Rgb& radiance, double tnear, ShadowBatch& out) {
  const SampleBatch& samples = hits.draws;
  const D d;
  const std::size_t n = hits.padded_size(), lanes = hn::Lanes(d);
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), infinity = hn::Set(d, std::numeric_limits<double>::infinity());
  std::size_t size = out.size();
  out.reserve(size + n + lanes);
  const V r = hn::Set(d, radiance.r), g = hn::Set(d, radiance.g), b = hn::Set(d, radiance.b);
  for (std::size_t k = 0; k < n; k += lanes) {
    const FrameV frame = frame_at(d, hits, k);
    const Vec3V o{load(d, samples.ox, k), load(d, samples.oy, k), load(d, samples.oz, k)};
    const Vec3V i{load(d, samples.ix, k), load(d, samples.iy, k), load(d, samples.iz, k)};
    const M found = hn::And(real(d, k, hits.size()), load(d, samples.found, k) != zero);
    size += append(d, found, {o, i, frame.to_world(i), one, infinity, r, g, b, zero, load(d, hits.owner, k)}, origin_at(d, hits, k),
                   hn::Set(d, tnear), out, size);
  }
  out.set_size(size);
}

void ShadowValues(ShadowBatch& batch, const SlotRanges& ranges) {
  const D d;
  const std::size_t lanes = hn::Lanes(d), n = batch.padded_size();
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0);
  for (std::size_t k = 0; k < n; k += lanes) {
    // Which slot each lane holds: the ranges are contiguous, so compare the lane's index with their starts.
    const V index = hn::Iota(d, double(k));
    const M env_light = index < hn::Set(d, double(ranges.lights_begin));
    const M brdf = index >= hn::Set(d, double(ranges.brdf_begin));
    const V pdf = load(d, batch.pdf, k), cos_i = load(d, batch.iz, k);
    // value = f x arriving x factor. A light: factor cos. The environment's light sample and the BRDF's,
    // each weighted against the other: factor = power_heuristic_factor(cos, p, q) (render/mis.h), p its own
    // density and q the other's, in lanes (a BRDF sample against q = 0, a constant environment's, weighs 1:
    // cos / p).
    V factor = cos_i;
    const M weighted = hn::Or(env_light, brdf);
    if (!hn::AllFalse(d, weighted)) {
      const V light_pdf = load(d, batch.light_pdf, k), sum = light_pdf * light_pdf + pdf * pdf;
      const V p = hn::IfThenElse(env_light, light_pdf, pdf), q = hn::IfThenElse(env_light, pdf, light_pdf);
      const M some = sum >= hn::Set(d, std::numeric_limits<double>::min());  // not underflowed
      V mis = hn::IfThenElseZero(some, lanes::divide(d, cos_i * p, hn::IfThenElse(some, sum, one)));
      const M tiny = hn::AndNot(some, hn::And(weighted, p > zero));
      if (HWY_UNLIKELY(!hn::AllFalse(d, tiny))) {
        const V safe_p = hn::IfThenElse(tiny, p, one);
        mis = hn::IfThenElse(tiny, cos_i / (safe_p + q * (q / safe_p)), mis);
      }
      factor = hn::IfThenElse(weighted, mis, cos_i);
    }
    double* value[3] = {batch.value_r.data(), batch.value_g.data(), batch.value_b.data()};
    const V f[3] = {load(d, batch.r, k), load(d, batch.g, k), load(d, batch.b, k)};
    const V arriving[3] = {load(d, batch.arriving_r, k), load(d, batch.arriving_g, k), load(d, batch.arriving_b, k)};
    for (int c = 0; c < 3; ++c) hn::StoreU(f[c] * arriving[c] * factor, d, value[c] + k);
    hn::StoreU(hn::IfThenElse(hn::AndNot(pdf > zero, brdf), zero, one), d, batch.casts.data() + k);
  }
}

void AddSamples(const double* const radiance[3], const double* alpha, double* const sum[4], std::size_t n) {
  const D d;
  const std::size_t lanes = hn::Lanes(d);
  std::size_t k = 0;
  for (; k + lanes <= n; k += lanes) {
    const V r = hn::LoadU(d, radiance[0] + k), g = hn::LoadU(d, radiance[1] + k), b = hn::LoadU(d, radiance[2] + k);
    // x - x is 0 for a finite x, NaN otherwise.
    const M finite = ((r - r) + (g - g) + (b - b)) == hn::Zero(d);
    hn::StoreU(hn::LoadU(d, sum[0] + k) + hn::IfThenElseZero(finite, r), d, sum[0] + k);
    hn::StoreU(hn::LoadU(d, sum[1] + k) + hn::IfThenElseZero(finite, g), d, sum[1] + k);
    hn::StoreU(hn::LoadU(d, sum[2] + k) + hn::IfThenElseZero(finite, b), d, sum[2] + k);
    hn::StoreU(hn::LoadU(d, sum[3] + k) + hn::LoadU(d, alpha + k), d, sum[3] + k);
  }
  for (; k < n; ++k) {
    const bool finite = (radiance[0][k] - radiance[0][k]) + (radiance[1][k] - radiance[1][k]) + (radiance[2][k] - radiance[2][k]) == 0.0;
    for (int c = 0; c < 3; ++c) sum[c][k] += finite ? radiance[c][k] : 0.0;
    sum[3][k] += alpha[k];
  }
}

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace facetfit
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "render/simd_dispatch.h"
namespace facetfit {

void place_hits(const TileHits& tile, const Vec3& camera, double eps, double material, const Vec3* tangent, bool positions, HitBatch& out,
                SimdTarget target) {
  FACETFIT_DISPATCH(target, PlaceHits, tile, camera, eps, material, tangent, positions, out);
}

void take_hits(const RayHits& hits, const LaneObjects& objects, const Rgb& background, TileHits& tile, double* alpha,
               double* const radiance[3], SimdTarget target) {
  FACETFIT_DISPATCH(target, TakeHits, hits, objects, background, tile, alpha, radiance);
}

void light_slots(const HitBatch& hits, const std::vector<LaneLight>& lights, double tnear, ShadowBatch& out, SlotRanges& ranges,
                 SimdTarget target) {
  for (const LaneLight& light : lights)
    if (!light.directional && !hits.positions) throw std::invalid_argument("light_slots: a point light needs the hits' positions");
  FACETFIT_DISPATCH(target, LightSlots, hits, lights, tnear, out, ranges);
}

void brdf_slots(const HitBatch& hits, const Rgb& radiance, double tnear, ShadowBatch& out, SimdTarget target) {
  FACETFIT_DISPATCH(target, BrdfSlots, hits, radiance, tnear, out);
}

void shadow_values(ShadowBatch& batch, const SlotRanges& ranges, SimdTarget target) {
  FACETFIT_DISPATCH(target, ShadowValues, batch, ranges);
}

void add_samples(const double* const radiance[3], const double* alpha, double* const sum[4], std::size_t n, SimdTarget target) {
  FACETFIT_DISPATCH(target, AddSamples, radiance, alpha, sum, n);
}

}  // namespace facetfit
#endif
