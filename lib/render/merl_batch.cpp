// Compiled once per SIMD target by Highway's foreach_target (this file includes itself), as
// render/ggx_batch.cpp.
#include "render/simd_targets.h"  // before any of Highway's headers
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "render/merl_batch.cpp"
#include <hwy/foreach_target.h>  // before highway.h

#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

#include "io/merl.h"
#include "render/lanes-inl.h"
#include "render/merl_batch.h"

HWY_BEFORE_NAMESPACE();
namespace facetfit {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace {

using lanes::D;
using lanes::V;

// atan2(y, x) in (-pi, pi] from Highway's arc tangent of the smaller of |y|, |x| over the larger.
V atan2(D d, V y, V x) {
  const V ax = hn::Abs(x), ay = hn::Abs(y);
  const auto steep = ay > ax;
  const V num = hn::IfThenElse(steep, ax, ay), den = hn::IfThenElse(steep, ay, ax);
  V a = hn::IfThenElseZero(den > hn::Zero(d), hn::Atan(d, lanes::divide(d, num, hn::IfThenElse(den > hn::Zero(d), den, hn::Set(d, 1.0)))));
  a = hn::IfThenElse(steep, hn::Set(d, 0.5 * kPi) - a, a);
  a = hn::IfThenElse(x < hn::Zero(d), hn::Set(d, kPi) - a, a);
  return hn::CopySign(a, y);
}

// The two neighbours along a theta axis of `res` bins at bin coordinate x >= 0, and the second's weight:
// the last bin clamps (HalfDiffTable::eval_linear).
struct Axis {
  V i0, i1, t;
};
Axis clamped(D d, V x, int res) {
  const V last = hn::Set(d, res - 1.0);
  const V i0 = hn::Min(hn::Floor(x), last);
  const auto at_end = i0 >= last;
  return {i0, hn::IfThenElse(at_end, last, i0 + hn::Set(d, 1.0)), hn::IfThenElseZero(hn::Not(at_end), x - i0)};
}

}  // namespace

void EvalMerlBatch(const MerlBatchModel& model, EvaluationBatch& batch) {
  const D d;
  const hn::Rebind<float, D> df;
  const hn::Rebind<std::int32_t, D> di;
  const std::size_t n = batch.padded_size();
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), pi = hn::Set(d, kPi), half_pi = hn::Set(d, 0.5 * kPi);
  double* out[3] = {batch.r.data(), batch.g.data(), batch.b.data()};
  for (std::size_t k = 0; k < n; k += hn::Lanes(d)) {
    const V ox = hn::LoadU(d, batch.ox.data() + k), oy = hn::LoadU(d, batch.oy.data() + k), oz = hn::LoadU(d, batch.oz.data() + k);
    const V ix = hn::LoadU(d, batch.ix.data() + k), iy = hn::LoadU(d, batch.iy.data() + k), iz = hn::LoadU(d, batch.iz.data() + k);
    const auto above = hn::And(iz > zero, oz > zero);
    // Half/diff angles (core/halfdiff.h): h = (i + o) / |i + o|, d = R_y(-theta_h) R_z(-phi_h) i.
    V hx = ix + ox, hy = iy + oy, hz = iz + oz;
    const V len = hn::Sqrt(hx * hx + hy * hy + hz * hz);
    const auto long_enough = len > hn::Set(d, 1e-12);
    // Divided, as halfdiff does: sqrt(theta_h) indexes the table, and near the pole the last bit of h moves it.
    const V safe_len = hn::IfThenElse(long_enough, len, one);
    hx = hn::IfThenElseZero(long_enough, hx / safe_len), hy = hn::IfThenElseZero(long_enough, hy / safe_len);
    hz = hn::IfThenElse(long_enough, hz / safe_len, one);
    const V ct = hn::Min(hn::Max(hz, hn::Set(d, -1.0)), one);
    const V theta_h = lanes::acos(d, ct);
    const V r = hn::Sqrt(hx * hx + hy * hy);
    const auto turned = r > zero;
    const V inv_r = lanes::reciprocal(d, hn::IfThenElse(turned, r, one));
    const V c = hn::IfThenElse(turned, hx * inv_r, one), s = hn::IfThenElseZero(turned, hy * inv_r);
    const V tx = c * ix + s * iy, ty = hn::Neg(s) * ix + c * iy, tz = iz;
    const V dx = ct * tx - r * tz, dy = ty, dz = r * tx + ct * tz;
    const V theta_d = lanes::acos(d, hn::Min(hn::Max(dz, hn::Set(d, -1.0)), one));
    V phi_d = atan2(d, dy, dx);
    phi_d = hn::IfThenElse(phi_d < zero, phi_d + pi, phi_d);  // reciprocity: period pi
    phi_d = hn::IfThenElse(phi_d >= pi, phi_d - pi, phi_d);
    // Bin coordinates (bin i of each axis at coordinate i), and the neighbours around them.
    const Axis ah = clamped(d, hn::Sqrt(hn::Max(zero, theta_h) / half_pi) * hn::Set(d, HalfDiffTable::kThetaH), HalfDiffTable::kThetaH);
    const Axis ad = clamped(d, theta_d / half_pi * hn::Set(d, HalfDiffTable::kThetaD), HalfDiffTable::kThetaD);
    const V x_p = phi_d / pi * hn::Set(d, HalfDiffTable::kPhiD);
    const V p0 = hn::Min(hn::Floor(x_p), hn::Set(d, HalfDiffTable::kPhiD - 1.0));
    const Axis ap{p0, hn::IfThenElseZero(p0 < hn::Set(d, HalfDiffTable::kPhiD - 1.0), p0 + one), x_p - p0};
    // Missing neighbours (NaN) drop out and the remaining weights are renormalized, per channel.
    V sum[3] = {zero, zero, zero}, weight[3] = {zero, zero, zero};
    for (int corner = 0; corner < 8; ++corner) {
      const V w = ((corner & 1) ? ah.t : one - ah.t) * ((corner & 2) ? ad.t : one - ad.t) * ((corner & 4) ? ap.t : one - ap.t);
      const auto counts = w > zero;
      const V i = (corner & 1) ? ah.i1 : ah.i0, j = (corner & 2) ? ad.i1 : ad.i0, p = (corner & 4) ? ap.i1 : ap.i0;
      const V bin = p + hn::Set(d, HalfDiffTable::kPhiD) * (j + hn::Set(d, HalfDiffTable::kThetaD) * i);  // HalfDiffTable::index
      const auto index = hn::DemoteTo(di, bin);
      for (int ch = 0; ch < 3; ++ch) {
        const V v = hn::PromoteTo(d, hn::GatherIndex(df, model.channel[ch], index));
        const auto valid = hn::And(counts, v == v);  // NaN: missing
        sum[ch] = hn::IfThenElse(valid, sum[ch] + w * v, sum[ch]);
        weight[ch] = hn::IfThenElse(valid, weight[ch] + w, weight[ch]);
      }
    }
    // A channel with no measured neighbour is 0 beside the others (HalfDiffTable::eval_linear).
    for (int ch = 0; ch < 3; ++ch) {
      const auto measured = hn::And(above, weight[ch] > zero);
      hn::StoreU(hn::IfThenElseZero(measured, lanes::divide(d, sum[ch], hn::IfThenElse(measured, weight[ch], one))), d, out[ch] + k);
    }
  }
}

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace facetfit
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "render/simd_dispatch.h"
namespace facetfit {

std::optional<MerlBatchModel> MerlBatchModel::of(const HalfDiffTable& table) {
  if (table.lookup() != HalfDiffTable::Lookup::linear) return std::nullopt;
  MerlBatchModel m;
  for (int c = 0; c < 3; ++c) m.channel[c] = table.channel(c);
  return m;
}

void eval_merl_batch(const MerlBatchModel& model, EvaluationBatch& batch, SimdTarget target) {
  FACETFIT_DISPATCH(target, EvalMerlBatch, model, batch);
}

}  // namespace facetfit
#endif
