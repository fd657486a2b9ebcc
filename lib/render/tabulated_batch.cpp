// Compiled once per SIMD target by Highway's foreach_target (this file includes itself), as
// render/ggx_batch.cpp.
#include "render/simd_targets.h"  // before any of Highway's headers
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "render/tabulated_batch.cpp"
#include <hwy/foreach_target.h>  // before highway.h

#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

#include "model/tabulated.h"
#include "model/visible_azimuth.h"
#include "render/lanes-inl.h"
#include "render/tabulated_batch.h"

HWY_BEFORE_NAMESPACE();
namespace facetfit {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace {

using lanes::D;
using lanes::DI;
using lanes::V;
using I = hn::Vec<DI>;

// Interval j and fraction t of the theta grid at theta = acos(c), c in [-1, 1] (ThetaGrid::locate).
struct GridPosition {
  I j;
  V t;
};
HWY_INLINE GridPosition locate(D d, V c, int resolution) {
  const DI di;
  const V theta = lanes::acos(d, hn::Min(hn::Max(c, hn::Set(d, -1.0)), hn::Set(d, 1.0)));
  const V x = hn::Min(lanes::sqrt(d, hn::Max(hn::Zero(d), theta) * hn::Set(d, 2.0 / kPi)), hn::Set(d, 1.0)) * hn::Set(d, double(resolution));
  const I j = hn::Min(hn::ConvertTo(di, x), hn::Set(di, resolution - 1));
  return {j, x - hn::ConvertTo(d, j)};
}

// The Catmull-Rom spline through `values` at p (ThetaGrid::interpolate): node j - 1 mirrored to node 1
// at j = 0, the ghost past the last node folded into the weights of the last two.
V spline(D d, const double* values, const GridPosition& p, int resolution) {
  const DI di;
  const V t = p.t, t2 = t * t, t3 = t2 * t, half = hn::Set(d, 0.5);
  const V w0 = half * (hn::Neg(t) + hn::Set(d, 2.0) * t2 - t3);
  V w1 = half * (hn::Set(d, 2.0) - hn::Set(d, 5.0) * t2 + hn::Set(d, 3.0) * t3);
  V w2 = half * (t + hn::Set(d, 4.0) * t2 - hn::Set(d, 3.0) * t3);
  V w3 = half * (t3 - t2);
  const I one = hn::Set(di, 1);
  const I i0 = hn::IfThenElse(p.j == hn::Zero(di), one, p.j - one);
  const auto past = hn::RebindMask(d, p.j + hn::Set(di, 2) > hn::Set(di, resolution));
  w2 = hn::IfThenElse(past, w2 + hn::Set(d, 2.0) * w3, w2);
  w1 = hn::IfThenElse(past, w1 - w3, w1);
  w3 = hn::IfThenElseZero(hn::Not(past), w3);
  const I i3 = hn::Min(p.j + hn::Set(di, 2), hn::Set(di, resolution));
  V v = w0 * hn::GatherIndex(d, values, i0);
  v = v + w1 * hn::GatherIndex(d, values, p.j);
  v = v + w2 * hn::GatherIndex(d, values, p.j + one);
  return v + w3 * hn::GatherIndex(d, values, i3);
}

// G1 of the table (G1Table::operator()) at c = cos(theta) > 0; lanes at or below the horizon read 0.
V g1(D d, const TabulatedBatchModel& model, V c) {
  const DI di;
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), scale = hn::Set(d, double(model.g1_size));
  const V cz = hn::Max(c, zero);
  const V x = hn::Sqrt(cz) * scale;
  const I m = hn::Min(hn::ConvertTo(di, x), hn::Set(di, model.g1_size - 1));
  const V t = x - hn::ConvertTo(d, m);
  const V lo = hn::GatherIndex(d, model.g1_ratios, m), hi = hn::GatherIndex(d, model.g1_ratios, m + hn::Set(di, 1));
  const V ratio = hn::IfThenElse(x >= scale, hn::Set(d, model.g1_ratios[model.g1_size]), lo + t * (hi - lo));
  return hn::IfThenElseZero(c > zero, hn::Min(one, cz * ratio));
}

// 2 integral over phi of max(0, a cos(phi) + b), a, b >= 0 (positive_phi_integral).
V positive_phi_integral(D d, V a, V b) {
  const auto whole = a <= b;
  const V safe_a = hn::IfThenElse(whole, hn::Set(d, 1.0), a);
  const V ratio = hn::Max(lanes::divide(d, hn::Neg(b), safe_a), hn::Set(d, -1.0));
  const V part = hn::Set(d, 2.0) * (hn::Sqrt(hn::Max(hn::Zero(d), a * a - b * b)) + b * lanes::acos(d, ratio));
  return hn::IfThenElse(whole, hn::Set(d, 2.0 * kPi) * b, part);
}

// AzimuthGuess::operator() (model/visible_azimuth.h) on `values`, its table; lanes where a + b = 0 read
// any node. s = a / (a + b) by the lanes' division (a few ulp from the one-pair path's): only the start
// of Newton's steps, not their root.
V azimuth_guess(D d, const double* values, V a, V b, V u, V phi_max) {
  const DI di;
  constexpr int n = AzimuthGuess::kSize;
  const V sum = a + b;
  // s clamped as AzimuthGuess does: lanes the caller discards (a view below the horizon: b < 0) would
  // otherwise extrapolate far outside [0, phi_max] and hold the vector's Newton loop for ~25 bisections.
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0);
  const V s = lanes::divide(d, a, hn::IfThenElse(sum > zero, sum, one));
  const V x = hn::Min(hn::Max(s, zero), one) * hn::Set(d, double(n));
  const V y = hn::Min(hn::Max(u, zero), one) * hn::Set(d, double(n));
  const I i = hn::Min(hn::ConvertTo(di, x), hn::Set(di, n - 1)), j = hn::Min(hn::ConvertTo(di, y), hn::Set(di, n - 1));
  const V t = x - hn::ConvertTo(d, i), w = y - hn::ConvertTo(d, j);
  const I next_row = hn::Set(di, AzimuthGuess::kStride), at = i * next_row + j, next = hn::Set(di, 1);
  const V v00 = hn::GatherIndex(d, values, at), v01 = hn::GatherIndex(d, values, at + next);
  const V v10 = hn::GatherIndex(d, values, at + next_row), v11 = hn::GatherIndex(d, values, at + next_row + next);
  const V near = v00 + w * (v01 - v00), far = v10 + w * (v11 - v10);
  return (near + t * (far - near)) * phi_max;
}

// phi in (-pi, pi] with density proportional to max(0, a cos(phi) + b), a, b >= 0, from u in [0, 1), as
// (cos phi, sin phi): sample_visible_azimuth of model/visible_azimuth.h, its Newton steps on the CDF
// a sin(phi) + b phi from the table's guess in every lane until each has stopped (2 steps for most, at
// most 40).
lanes::CosSin sample_phi(D d, const double* guess, V a, V b, V u) {
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), two = hn::Set(d, 2.0), half = hn::Set(d, 0.5), pi = hn::Set(d, kPi);
  const auto whole = a <= b;
  const V ratio = hn::Min(hn::Max(lanes::divide(d, hn::Neg(b), hn::IfThenElse(whole, one, a)), hn::Set(d, -1.0)), one);
  const V phi_max = hn::IfThenElse(whole, pi, lanes::acos(d, ratio));
  const auto lower = u < half;
  const V sign = hn::IfThenElse(lower, hn::Set(d, -1.0), one);
  u = hn::IfThenElse(lower, two * u, two * u - one);
  // sin(phi_max) = sqrt(1 - ratio^2) where a > b, 0 where a <= b.
  const V total = hn::IfThenElseZero(hn::Not(whole), a * hn::Sqrt(hn::Max(zero, one - ratio * ratio))) + b * phi_max;
  const auto flat = hn::Not(total > zero);
  const V target = u * total;
  V lo = zero, hi = phi_max, phi = azimuth_guess(d, guess, a, b, u, phi_max), c = one, s = zero;
  auto active = hn::Not(flat);
  for (int it = 0; it < 40 && !hn::AllFalse(d, active); ++it) {
    const lanes::CosSin at = lanes::cos_sin(d, phi);
    const V sin_phi = at.s, cos_phi = at.c;
    const V f = a * sin_phi + b * phi - target;
    const auto beyond = f > zero;
    hi = hn::IfThenElse(beyond, phi, hi), lo = hn::IfThenElse(beyond, lo, phi);
    const V df = a * cos_phi + b, mid = half * (lo + hi);
    V next = hn::IfThenElse(df > zero, phi - lanes::divide(d, f, hn::IfThenElse(df > zero, df, one)), mid);
    next = hn::IfThenElse(hn::And(next >= lo, next <= hi), next, mid);
    const V step = next - phi;
    // Stopped: the rotation by the last step to first order.
    const auto stops = hn::And(active, hn::Abs(step) < hn::Set(d, 1e-7));
    c = hn::IfThenElse(stops, cos_phi - sin_phi * step, c), s = hn::IfThenElse(stops, sin_phi + cos_phi * step, s);
    active = hn::AndNot(stops, active);
    phi = hn::IfThenElse(active, next, phi);
  }
  if (!hn::AllFalse(d, active)) {
    const lanes::CosSin at = lanes::cos_sin(d, phi);
    c = hn::IfThenElse(active, at.c, c), s = hn::IfThenElse(active, at.s, s);
  }
  if (!hn::AllFalse(d, flat)) {  // no density: uniform
    const V uniform = u * pi;
    const lanes::CosSin at = lanes::cos_sin(d, uniform);
    c = hn::IfThenElse(flat, at.c, c), s = hn::IfThenElse(flat, at.s, s);
  }
  return {c, sign * s};
}

// o reflected about a normal drawn from the lobe's visible normals seen from o: i
// (TabulatedMicrofacet::lobe_direction, unstretched), to be refused where i.z <= 0.
lanes::Direction lobe_direction(D d, const TabulatedBatchModel& model, V ox, V oy, V oz, V u1, V u2) {
  const DI di;
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0);
  const int r = model.resolution;
  // One of the two view slices around o with the weights of the mixture, reusing u1.
  const GridPosition view = locate(d, oz, r);
  const V keep = one - view.t;
  const auto first = u1 < keep;
  V u = lanes::divide(d, hn::IfThenElse(first, u1, u1 - keep), hn::IfThenElse(first, keep, hn::IfThenElse(view.t > zero, view.t, one)));
  u = hn::Min(hn::Max(u, zero), hn::Set(d, 1.0 - 1e-16));
  const I slice = hn::IfThenElse(hn::RebindMask(di, first), view.j, view.j + hn::Set(di, 1));
  // The interval of theta_h: the last node of the slice's running sums <= u (sample_cdf: zero-mass
  // intervals are never chosen), by bisection between the guide's entries around u.
  const I row = slice * hn::Set(di, r + 1), last = hn::Set(di, r);
  constexpr int guide = TabulatedMicrofacet::kCdfGuide;
  const I at = slice * hn::Set(di, guide + 1) + hn::Min(hn::ConvertTo(di, u * hn::Set(d, double(guide))), hn::Set(di, guide - 1));
  I k = hn::GatherIndex(di, model.cdf_guide, at), top = hn::GatherIndex(di, model.cdf_guide, at + hn::Set(di, 1));
  // The running sum at node k is <= u; the last such node is at most `top`.
  for (auto open = top > k; !hn::AllFalse(di, open); open = top > k) {
    const I probe = hn::ShiftRight<1>(k + top + hn::Set(di, 1));
    const auto take = hn::RebindMask(di, hn::GatherIndex(d, model.cdf, row + probe) <= u);
    k = hn::IfThenElse(take, probe, k), top = hn::IfThenElse(take, top, probe - hn::Set(di, 1));
  }
  k = hn::Min(k, last - hn::Set(di, 1));
  const V c0 = hn::GatherIndex(d, model.cdf, row + k), c1 = hn::GatherIndex(d, model.cdf, row + k + hn::Set(di, 1));
  const V mass = c1 - c0;
  const auto some = mass > zero;
  const V frac = hn::IfThenElse(some, hn::Min(hn::Max(lanes::divide(d, u - c0, hn::IfThenElse(some, mass, one)), zero), one), hn::Set(d, 0.5));
  // Uniform in cos(theta_h) within the interval.
  const V n0 = hn::GatherIndex(d, model.cos_nodes, k), n1 = hn::GatherIndex(d, model.cos_nodes, k + hn::Set(di, 1));
  const V cos_h = n0 - frac * (n0 - n1);
  const V sin_h = hn::Sqrt(hn::Max(zero, one - cos_h * cos_h)), sin_o = hn::Sqrt(hn::Max(zero, one - oz * oz));
  // phi relative to o's azimuth, then turned to it by o.xy / |o.xy|.
  const lanes::CosSin phi = sample_phi(d, model.azimuth_guess, sin_o * sin_h, oz * cos_h, u2);
  V hx = sin_h * phi.c, hy = sin_h * phi.s;
  const V o_xy = hn::Sqrt(ox * ox + oy * oy);
  const auto turned = hn::And(sin_o > zero, o_xy > zero);
  const V per_xy = lanes::reciprocal(d, hn::IfThenElse(turned, o_xy, one)), turn_c = ox * per_xy, turn_s = oy * per_xy;
  const V tx = turn_c * hx - turn_s * hy, ty = turn_s * hx + turn_c * hy;
  hx = hn::IfThenElse(turned, tx, hx), hy = hn::IfThenElse(turned, ty, hy);
  const V two_o_h = hn::Set(d, 2.0) * (ox * hx + oy * hy + oz * cos_h);
  return {two_o_h * hx - ox, two_o_h * hy - oy, two_o_h * cos_h - oz};
}

}  // namespace

void SampleTabulatedBatch(const TabulatedBatchModel& model, SampleBatch& batch) {
  const D d;
  lanes::sample_proposal(d, model.weights, model.coat, batch, [&](V ox, V oy, V oz, V u1, V u2, V, V) {
    return lobe_direction(d, model, ox, oy, oz, u1, u2);
  });
}

void EvalTabulatedBatch(const TabulatedBatchModel& model, EvaluationBatch& batch, bool with_f) {
  const D d;
  const DI di;
  const std::size_t n = batch.padded_size();
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), four = hn::Set(d, 4.0);
  const int resolution = model.resolution;
  const V body[3] = {hn::Set(d, model.body.r * kInvPi), hn::Set(d, model.body.g * kInvPi), hn::Set(d, model.body.b * kInvPi)};
  const bool minnaert = model.body_exponent != 1.0;
  const V body_power = hn::Set(d, model.body_exponent - 1.0), body_scale = hn::Set(d, 0.5 * (model.body_exponent + 1.0));
  const bool coat = model.coat.present();
  double* out[3] = {batch.r.data(), batch.g.data(), batch.b.data()};
  for (std::size_t k = 0; k < n; k += hn::Lanes(d)) {
    const V ox = hn::LoadU(d, batch.ox.data() + k), oy = hn::LoadU(d, batch.oy.data() + k), oz = hn::LoadU(d, batch.oz.data() + k);
    const V ix = hn::LoadU(d, batch.ix.data() + k), iy = hn::LoadU(d, batch.iy.data() + k), iz = hn::LoadU(d, batch.iz.data() + k);
    const auto above = hn::And(iz > zero, oz > zero);
    // h = normalize(i + o)
    V hx = ix + ox, hy = iy + oy, hz = iz + oz;
    const V inv_len = lanes::inverse_sqrt(d, hx * hx + hy * hy + hz * hz);
    hx = hx * inv_len, hy = hy * inv_len, hz = hz * inv_len;
    const auto h_up = hz > zero;
    // theta_h once, for D and for the normal's place on the grid.
    const GridPosition normal = locate(d, hn::IfThenElse(h_up, hz, one), resolution);
    const V four_cos = four * iz * oz;
    const V cos_d = hn::Min(hn::Max(ix * hx + iy * hy + iz * hz, zero), one);
    const V o_dot_h = ox * hx + oy * hy + oz * hz;
    const auto o_faces_h = o_dot_h > zero;
    V coat_f = zero, coat_pdf = zero;
    if (coat) {
      const lanes::CoatTerms terms = lanes::coat_terms(d, model.coat, ox, oy, oz, ix, iy, iz, hx, hy, hz, cos_d, four_cos, o_faces_h);
      coat_f = terms.f, coat_pdf = terms.pdf;
    }
    if (with_f) {
      const V dh = hn::IfThenElseZero(h_up, hn::Max(zero, spline(d, model.ndf, normal, model.resolution)));
      const V g1_i = g1(d, model, iz), g1_o = g1(d, model, oz);
      V g2;
      switch (model.smith) {
        case Smith::masking: g2 = hn::Min(g1_i, g1_o); break;
        case Smith::correlated: {
          const V den = g1_i + g1_o - g1_i * g1_o;
          g2 = hn::IfThenElseZero(den > zero, lanes::divide(d, g1_i * g1_o, hn::IfThenElse(den > zero, den, one)));
          break;
        }
        case Smith::separable: g2 = g1_i * g1_o; break;
      }
      V fresnel[3];
      lanes::fresnel_curve(d, model.curve, cos_d, fresnel);
      const V specular = lanes::divide(d, dh * g2, four_cos);
      // f where cos(theta_i) cos(theta_o) does not underflow (above_horizon, core/vec.h)
      const auto formed = hn::And(above, iz * oz > zero);
      // Minnaert's factor (k + 1) / 2 (cos_i cos_o)^(k - 1) (model/body.h)
      const V factor = minnaert ? body_scale * hn::Exp(d, body_power * hn::Log(d, hn::Max(iz * oz, hn::Set(d, 1e-300)))) : one;
      for (int c = 0; c < 3; ++c) hn::StoreU(hn::IfThenElseZero(formed, body[c] * factor + fresnel[c] * specular + coat_f), d, out[c] + k);
    }

    // The lobe's visible normals (TabulatedMicrofacet::measured_visible_normal_pdf): the density per
    // cos(theta_h) of the normal's interval, mixed linearly between the two view slices around o, spread
    // over phi as max(0, o.h); reflected about h, d(omega_i) = 4 (o.h) d(omega_h).
    // A light's slots take f alone (shading_batch.h): where no lane of the vector asks, no density.
    if (hn::AllFalse(d, hn::LoadU(d, batch.with_pdf.data() + k) != zero)) {
      hn::StoreU(zero, d, batch.pdf.data() + k);
      continue;
    }
    const GridPosition view = locate(d, oz, resolution);
    const I at = view.j * hn::Set(di, resolution) + normal.j;
    const V per_cos_lo = hn::GatherIndex(d, model.visible_density, at);
    const V per_cos_hi = hn::GatherIndex(d, model.visible_density, at + hn::Set(di, resolution));
    const V per_cos = (one - view.t) * per_cos_lo + view.t * per_cos_hi;
    const V sin_o = hn::Sqrt(hn::Max(zero, one - oz * oz)), sin_h = hn::Sqrt(hn::Max(zero, one - hz * hz));
    const V phi_total = positive_phi_integral(d, sin_o * sin_h, oz * hz);
    const auto visible = hn::And(hn::And(o_faces_h, h_up), hn::And(per_cos > zero, phi_total > zero));
    const V safe_total = hn::IfThenElse(visible, phi_total, one);
    // per_cos (o.h) / total / (4 o.h): o.h cancels.
    const V lobe_pdf = hn::IfThenElseZero(visible, lanes::divide(d, per_cos, four * safe_total));
    hn::StoreU(hn::IfThenElseZero(above, lanes::mixture_density(d, model.weights, coat, lobe_pdf, coat_pdf, iz)), d, batch.pdf.data() + k);
  }
}

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace facetfit
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "render/simd_dispatch.h"

namespace facetfit {

std::optional<TabulatedBatchModel> TabulatedBatchModel::of(const TabulatedMicrofacet& lobe, double lobe_weight) {
  if (!lobe.stretch().identity() || !lobe.can_sample()) return std::nullopt;
  const MicrofacetTables& tables = lobe.tables();
  if (tables.fresnel.value.size() != std::size_t(FresnelCurve::kSize)) return std::nullopt;
  TabulatedBatchModel m;
  m.resolution = tables.ndf.grid.resolution;
  m.ndf = tables.ndf.ndf.data();
  m.cos_nodes = lobe.cos_nodes().data();
  m.cdf = lobe.sampling().cdf.data();
  m.visible_density = lobe.visible_density().data();
  m.cdf_guide = lobe.cdf_guide().data();
  m.g1_ratios = lobe.g1_table().ratios();
  m.g1_size = lobe.g1_table().size();
  m.smith = tables.smith;
  m.curve = tables.fresnel.value.data();
  m.body = tables.body;
  m.body_exponent = tables.body_exponent;
  m.azimuth_guess = AzimuthGuess::table().values();
  m.coat = tables.coat;
  m.weights = {lobe_weight, lobe.lobe_weight(), lobe.body_weight(), tables.coat.present() ? lobe.coat_weight() : 0.0};
  return m;
}

void eval_tabulated_batch(const TabulatedBatchModel& model, EvaluationBatch& batch, SimdTarget target, bool with_f) {
  FACETFIT_DISPATCH(target, EvalTabulatedBatch, model, batch, with_f);
}

void sample_tabulated_batch(const TabulatedBatchModel& model, SampleBatch& batch, SimdTarget target) {
  FACETFIT_DISPATCH(target, SampleTabulatedBatch, model, batch);
}

}  // namespace facetfit
#endif
