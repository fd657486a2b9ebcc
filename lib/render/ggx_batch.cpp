// Compiled once per SIMD target by Highway's foreach_target (this file includes itself): the targets of
// render/simd_targets.h, which the dispatch at the end picks between.
#include "render/simd_targets.h"  // before any of Highway's headers
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "render/ggx_batch.cpp"
#include <hwy/foreach_target.h>  // before highway.h

#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

#include "model/fresnel_curve.h"
#include "render/ggx_batch.h"

HWY_BEFORE_NAMESPACE();
namespace facetfit {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

namespace {

using D = hn::ScalableTag<double>;
using V = hn::Vec<D>;

// Smith's Lambda of GGX for w above the horizon: (sqrt(1 + alpha^2 tan^2) - 1) / 2, with
// alpha^2 sin^2 = wx^2 ax^2 + wy^2 ay^2; zero where that is (as for a denormal normal).
V lambda(D d, V wx, V wy, V wz, V ax2, V ay2) {
  const V a2t2 = (wx * wx * ax2 + wy * wy * ay2) / (wz * wz);
  const V one = hn::Set(d, 1.0), half = hn::Set(d, 0.5);
  return hn::IfThenElseZero(a2t2 > hn::Zero(d), half * (hn::Sqrt(one + a2t2) - one));
}

// D(h) of GGX for h above the horizon: ax^3 ay^3 / (pi e^2), e = hx^2 ay^2 + hy^2 ax^2 + hz^2 ax^2 ay^2.
V ndf(V hx, V hy, V hz, V ax2, V ay2, V numerator_over_pi) {
  const V e = hx * hx * ay2 + hy * hy * ax2 + hz * hz * ax2 * ay2;
  return numerator_over_pi / (e * e);
}

// (1 - mu)^5 of Schlick's approximation, mu clamped to [0, 1] as fresnel_schlick does.
V schlick_weight(D d, V cos_d) {
  const V m = hn::Min(hn::Max(hn::Set(d, 1.0) - cos_d, hn::Zero(d)), hn::Set(d, 1.0));
  return (m * m) * (m * m) * m;
}

struct Direction {
  V x, y, z;
};

// Visible normals of GGX (model/ggx_visible.h, Heitz 2018) for o above the horizon, with u1, u2 in [0, 1)
// and (cos, sin) of phi = 2 pi u2: i, to be refused where i.z <= 0.
Direction ggx_visible_direction(D d, V ox, V oy, V oz, V alpha, V u1, V cos_phi, V sin_phi) {
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), half = hn::Set(d, 0.5);
  // to the unit-roughness frame
  V vx = alpha * ox, vy = alpha * oy, vz = oz;
  const V inv_v = one / hn::Sqrt(vx * vx + vy * vy + vz * vz);
  vx = vx * inv_v, vy = vy * inv_v, vz = vz * inv_v;
  const V len2 = vx * vx + vy * vy;
  const auto tilted = len2 > zero;
  const V len = hn::Sqrt(hn::IfThenElse(tilted, len2, one));
  const V t1x = hn::IfThenElse(tilted, hn::Neg(vy) / len, one), t1y = hn::IfThenElseZero(tilted, vx / len);
  // t2 = v x t1, t1.z = 0 (written out as glm::cross does)
  const V t2x = vy * zero - t1y * vz, t2y = vz * t1x - zero * vx, t2z = vx * t1y - t1x * vy;
  const V r = hn::Sqrt(u1);
  const V p1 = r * cos_phi, s = half * (one + vz);
  const V p2 = (one - s) * hn::Sqrt(hn::Max(zero, one - p1 * p1)) + s * r * sin_phi;
  const V w = hn::Sqrt(hn::Max(zero, one - p1 * p1 - p2 * p2));
  const V nx = p1 * t1x + p2 * t2x + w * vx, ny = p1 * t1y + p2 * t2y + w * vy, nz = p1 * zero + p2 * t2z + w * vz;
  V hx = alpha * nx, hy = alpha * ny, hz = hn::Max(zero, nz);
  const V inv_h = one / hn::Sqrt(hx * hx + hy * hy + hz * hz);
  hx = hx * inv_h, hy = hy * inv_h, hz = hz * inv_h;
  const V two_o_h = hn::Set(d, 2.0) * (ox * hx + oy * hy + oz * hz);
  return {two_o_h * hx - ox, two_o_h * hy - oy, two_o_h * hz - oz};
}

}  // namespace

void SampleGgxBatch(const GgxBatchModel& model, SampleBatch& batch) {
  const D d;
  const std::size_t n = batch.padded_size();
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), two = hn::Set(d, 2.0), two_pi = hn::Set(d, 2.0 * kPi);
  const V quarter_pi = hn::Set(d, 0.25 * kPi), half_pi = hn::Set(d, 0.5 * kPi);
  const V alpha = hn::Set(d, model.alpha), coat_alpha = hn::Set(d, model.coat.alpha);
  const V lobe_weight = hn::Set(d, model.lobe_weight), part_lobe = hn::Set(d, model.part_lobe), part_body = hn::Set(d, model.part_body);
  const V part_coat = hn::Set(d, model.part_coat);
  const bool coat = model.coat.present(), body = model.part_body > 0.0;
  for (std::size_t k = 0; k < n; k += hn::Lanes(d)) {
    const V ox = hn::LoadU(d, batch.ox.data() + k), oy = hn::LoadU(d, batch.oy.data() + k), oz = hn::LoadU(d, batch.oz.data() + k);
    const V u1 = hn::LoadU(d, batch.u1.data() + k), u2 = hn::LoadU(d, batch.u2.data() + k), u3 = hn::LoadU(d, batch.u3.data() + k);
    const V phi = two_pi * u2, cos_phi = hn::Cos(d, phi), sin_phi = hn::Sin(d, phi);
    // The proposal (u3 < lobe_weight): u1 picks its part and is rescaled within it (ProposalParts::sample).
    const auto in_lobe = u1 < part_lobe;
    Direction i = ggx_visible_direction(d, ox, oy, oz, alpha, u1 / part_lobe, cos_phi, sin_phi);
    const V rest = u1 - part_lobe;
    auto refused = hn::Not(in_lobe);  // parts past the lobe that this model lacks
    if (body) {
      const auto in_body = hn::AndNot(in_lobe, rest < part_body);
      const V r = hn::Sqrt(rest / part_body);
      i.x = hn::IfThenElse(in_body, r * cos_phi, i.x), i.y = hn::IfThenElse(in_body, r * sin_phi, i.y);
      i.z = hn::IfThenElse(in_body, hn::Sqrt(hn::Max(zero, one - r * r)), i.z);
      refused = hn::AndNot(in_body, refused);
    }
    if (coat) {
      const auto in_coat = hn::AndNot(in_lobe, rest >= part_body);
      const V u = hn::Min(hn::Max((rest - part_body) / part_coat, zero), hn::Set(d, 1.0 - 1e-16));
      const Direction c = ggx_visible_direction(d, ox, oy, oz, coat_alpha, u, cos_phi, sin_phi);
      i.x = hn::IfThenElse(in_coat, c.x, i.x), i.y = hn::IfThenElse(in_coat, c.y, i.y), i.z = hn::IfThenElse(in_coat, c.z, i.z);
      refused = hn::AndNot(in_coat, refused);
    }
    // Cosine sampling otherwise, by the concentric map of the disc (ShadingModel::sample_direction).
    const auto cosine = u3 >= lobe_weight;
    const V a = two * u1 - one, b = two * u2 - one;
    const auto a_wins = hn::Abs(a) > hn::Abs(b), centre = hn::And(a == zero, b == zero);
    const V r = hn::IfThenElseZero(hn::Not(centre), hn::IfThenElse(a_wins, a, b));
    // Both ratios guarded: the lane that does not use one may divide by zero.
    const V ratio_ba = b / hn::IfThenElse(a == zero, one, a), ratio_ab = a / hn::IfThenElse(b == zero, one, b);
    const V disc_phi = hn::IfThenElseZero(hn::Not(centre), hn::IfThenElse(a_wins, quarter_pi * ratio_ba, half_pi - quarter_pi * ratio_ab));
    const V x = r * hn::Cos(d, disc_phi), y = r * hn::Sin(d, disc_phi);
    i.x = hn::IfThenElse(cosine, x, i.x), i.y = hn::IfThenElse(cosine, y, i.y);
    i.z = hn::IfThenElse(cosine, hn::Sqrt(hn::Max(zero, one - x * x - y * y)), i.z);
    refused = hn::AndNot(cosine, refused);
    // The proposal's parts refuse i below the horizon; the cosine's i.z >= 0 stands.
    const auto found = hn::AndNot(refused, hn::And(oz > zero, hn::Or(cosine, i.z > zero)));
    hn::StoreU(i.x, d, batch.ix.data() + k), hn::StoreU(i.y, d, batch.iy.data() + k), hn::StoreU(i.z, d, batch.iz.data() + k);
    hn::StoreU(hn::IfThenElseZero(found, one), d, batch.found.data() + k);
  }
}

void EvalGgxBatch(const GgxBatchModel& model, EvaluationBatch& batch) {
  const D d;
  const std::size_t n = batch.padded_size();
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), inv_pi = hn::Set(d, kInvPi);
  // The NDF's terms as Ndf::D and Ndf::lambda form them (alpha_x = alpha_y), for the same rounding.
  const double al = model.alpha, ca = model.coat.alpha;
  const V a2 = hn::Set(d, al * al), d_numerator = hn::Set(d, al * al * al * al * al * al / kPi);
  const bool coat = model.coat.present();
  const V cx2 = hn::Set(d, ca * ca), c_numerator = hn::Set(d, ca * ca * ca * ca * ca * ca / kPi);
  const Rgb& f0_rgb = model.f82_tint.f0;
  const Rgb& a_rgb = model.f82_tint.a;
  const V f0[3] = {hn::Set(d, f0_rgb.r), hn::Set(d, f0_rgb.g), hn::Set(d, f0_rgb.b)};
  const V a[3] = {hn::Set(d, a_rgb.r), hn::Set(d, a_rgb.g), hn::Set(d, a_rgb.b)};
  const V body[3] = {hn::Set(d, model.body.r * kInvPi), hn::Set(d, model.body.g * kInvPi), hn::Set(d, model.body.b * kInvPi)};
  double* out[3] = {batch.r.data(), batch.g.data(), batch.b.data()};
  const hn::RebindToSigned<D> di;
  for (std::size_t k = 0; k < n; k += hn::Lanes(d)) {
    const V ox = hn::LoadU(d, batch.ox.data() + k), oy = hn::LoadU(d, batch.oy.data() + k), oz = hn::LoadU(d, batch.oz.data() + k);
    const V ix = hn::LoadU(d, batch.ix.data() + k), iy = hn::LoadU(d, batch.iy.data() + k), iz = hn::LoadU(d, batch.iz.data() + k);
    const auto above = hn::And(iz > zero, oz > zero);
    // h = normalize(i + o)
    V hx = ix + ox, hy = iy + oy, hz = iz + oz;
    const V inv_len = one / hn::Sqrt(hx * hx + hy * hy + hz * hz);
    hx = hx * inv_len, hy = hy * inv_len, hz = hz * inv_len;
    const V dh = ndf(hx, hy, hz, a2, a2, d_numerator);
    const V lambda_o = lambda(d, ox, oy, oz, a2, a2), lambda_i = lambda(d, ix, iy, iz, a2, a2);
    V g2;
    switch (model.smith) {
      case Smith::masking: g2 = one / (one + hn::Max(lambda_i, lambda_o)); break;
      case Smith::correlated: g2 = one / (one + lambda_i + lambda_o); break;
      case Smith::separable: g2 = one / ((one + lambda_i) * (one + lambda_o)); break;
    }
    const V four_cos = hn::Set(d, 4.0) * iz * oz;
    const V cos_d = hn::Min(hn::Max(ix * hx + iy * hy + iz * hz, zero), one);
    const V specular = dh * g2 / four_cos;
    V fresnel[3];
    if (model.curve) {
      // Linear between the curve's entries, one per degree of theta_d (FresnelCurve::eval).
      constexpr int size = FresnelCurve::kSize;
      const V x = hn::Min(hn::Max(hn::Acos(d, cos_d) * hn::Set(d, size / (0.5 * kPi)), zero), hn::Set(d, size - 1.0));
      const auto j = hn::Min(hn::ConvertTo(di, x), hn::Set(di, std::int64_t{size - 2}));
      const V t = x - hn::ConvertTo(d, j);
      const auto j3 = j + j + j;  // three doubles per entry
      const double* base = &model.curve[0].r;
      for (int c = 0; c < 3; ++c) {
        const V lo = hn::GatherIndex(d, base + c, j3), hi = hn::GatherIndex(d, base + 3 + c, j3);
        fresnel[c] = lo * (one - t) + hi * t;
      }
    } else {
      const V m5 = schlick_weight(d, cos_d);
      const V m = one - cos_d, m2 = m * m, basis = cos_d * m2 * m2 * m2;
      for (int c = 0; c < 3; ++c) fresnel[c] = hn::Max(f0[c] + (one - f0[c]) * m5 - a[c] * basis, zero);
    }
    V coat_f = zero, coat_pdf = zero;
    const V o_dot_h = ox * hx + oy * hy + oz * hz;
    const auto o_faces_h = o_dot_h > zero;
    if (coat) {
      const V dc = ndf(hx, hy, hz, cx2, cx2, c_numerator);
      const V lc_o = lambda(d, ox, oy, oz, cx2, cx2), lc_i = lambda(d, ix, iy, iz, cx2, cx2);
      const V f0c = hn::Set(d, model.coat.f0);
      const V fc = f0c + (one - f0c) * schlick_weight(d, cos_d);
      coat_f = fc * dc * (one / (one + lc_i + lc_o)) / four_cos;
      coat_pdf = hn::IfThenElseZero(o_faces_h, (one / (one + lc_o)) * dc / (hn::Set(d, 4.0) * oz));
    }
    for (int c = 0; c < 3; ++c) hn::StoreU(hn::IfThenElseZero(above, body[c] + fresnel[c] * specular + coat_f), d, out[c] + k);
    // The proposal's parts, mixed with cosine sampling.
    const V lobe_pdf = hn::IfThenElseZero(o_faces_h, (one / (one + lambda_o)) * dh / (hn::Set(d, 4.0) * oz));
    V parts = hn::Set(d, model.part_lobe) * lobe_pdf + hn::Set(d, model.part_body) * iz * inv_pi;
    if (coat) parts = parts + hn::Set(d, model.part_coat) * coat_pdf;
    const V cosine = iz * inv_pi;
    const V pdf = hn::Set(d, model.lobe_weight) * parts + hn::Set(d, 1.0 - model.lobe_weight) * cosine;
    hn::StoreU(hn::IfThenElseZero(above, pdf), d, batch.pdf.data() + k);
  }
}

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace facetfit
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace facetfit {

void eval_ggx_batch(const GgxBatchModel& model, EvaluationBatch& batch, bool baseline) {
#if HWY_TARGETS & HWY_AVX2
  if (!baseline && cpu_has_avx2()) return N_AVX2::EvalGgxBatch(model, batch);
#endif
  HWY_STATIC_DISPATCH(EvalGgxBatch)(model, batch);
}

void sample_ggx_batch(const GgxBatchModel& model, SampleBatch& batch, bool baseline) {
#if HWY_TARGETS & HWY_AVX2
  if (!baseline && cpu_has_avx2()) return N_AVX2::SampleGgxBatch(model, batch);
#endif
  HWY_STATIC_DISPATCH(SampleGgxBatch)(model, batch);
}

}  // namespace facetfit
#endif
