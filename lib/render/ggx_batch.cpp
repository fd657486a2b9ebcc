// Compiled once per SIMD target by Highway's foreach_target (this file includes itself): the targets of
// render/simd_targets.h, which the dispatch at the end picks between.
#include "render/simd_targets.h"  // before any of Highway's headers
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "render/ggx_batch.cpp"
#include <hwy/foreach_target.h>  // before highway.h

#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

#include "render/ggx_batch.h"
#include "render/lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace facetfit {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using lanes::D;
using lanes::V;

void SampleGgxBatch(const GgxBatchModel& model, SampleBatch& batch) {
  const D d;
  const V alpha = hn::Set(d, model.alpha);
  lanes::sample_proposal(d, model.weights, model.coat, batch, true, [&](V ox, V oy, V oz, V u1, V, V cos_phi, V sin_phi) {
    return lanes::ggx_visible_direction(d, ox, oy, oz, alpha, u1, cos_phi, sin_phi);
  });
}

void EvalGgxBatch(const GgxBatchModel& model, EvaluationBatch& batch) {
  const D d;
  const std::size_t n = batch.padded_size();
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0);
  const lanes::LaneOps<D> op{d};
  // The NDF's terms as Ndf::D and Ndf::lambda form them (alpha_x = alpha_y), for the same rounding.
  const double al = model.alpha;
  const V a2 = hn::Set(d, al * al), d_numerator = hn::Set(d, al * al * al * al * al * al / kPi);
  const bool coat = model.coat.present();
  const Rgb& f0_rgb = model.f82_tint.f0;
  const Rgb& a_rgb = model.f82_tint.a;
  const V f0[3] = {hn::Set(d, f0_rgb.r), hn::Set(d, f0_rgb.g), hn::Set(d, f0_rgb.b)};
  const V a[3] = {hn::Set(d, a_rgb.r), hn::Set(d, a_rgb.g), hn::Set(d, a_rgb.b)};
  const V body[3] = {hn::Set(d, model.body.r * kInvPi), hn::Set(d, model.body.g * kInvPi), hn::Set(d, model.body.b * kInvPi)};
  double* out[3] = {batch.r.data(), batch.g.data(), batch.b.data()};
  for (std::size_t k = 0; k < n; k += hn::Lanes(d)) {
    const V ox = hn::LoadU(d, batch.ox.data() + k), oy = hn::LoadU(d, batch.oy.data() + k), oz = hn::LoadU(d, batch.oz.data() + k);
    const V ix = hn::LoadU(d, batch.ix.data() + k), iy = hn::LoadU(d, batch.iy.data() + k), iz = hn::LoadU(d, batch.iz.data() + k);
    const auto above = hn::And(iz > zero, oz > zero);
    // h = normalize(i + o)
    V hx = ix + ox, hy = iy + oy, hz = iz + oz;
    const V inv_len = lanes::inverse_sqrt(d, hx * hx + hy * hy + hz * hz);
    hx = hx * inv_len, hy = hy * inv_len, hz = hz * inv_len;
    const V dh = lanes::ggx_ndf(d, hx, hy, hz, a2, a2, d_numerator);
    const V lambda_o = lanes::ggx_lambda(d, ox, oy, oz, a2, a2), lambda_i = lanes::ggx_lambda(d, ix, iy, iz, a2, a2);
    const V g2 = lanes::smith_formulas::g2(op, model.smith, lambda_o, lambda_i);
    const V four_cos = hn::Set(d, 4.0) * iz * oz;
    const V cos_d = hn::Min(hn::Max(ix * hx + iy * hy + iz * hz, zero), one);
    const V specular = lanes::divide(d, dh * g2, four_cos);
    V fresnel[3];
    if (model.curve) {
      lanes::fresnel_curve(d, &model.curve[0].r, cos_d, fresnel);
    } else {
      const V m5 = lanes::fresnel_formulas::schlick_weight(op, cos_d), basis = lanes::fresnel_formulas::f82_basis(op, cos_d);
      for (int c = 0; c < 3; ++c) fresnel[c] = lanes::fresnel_formulas::f82_tint(op, f0[c], a[c], m5, basis);
    }
    V coat_f = zero, coat_pdf = zero;
    const V o_dot_h = ox * hx + oy * hy + oz * hz;
    const auto o_faces_h = o_dot_h > zero;
    if (coat) {
      const lanes::CoatTerms terms = lanes::coat_terms(d, model.coat, ox, oy, oz, ix, iy, iz, hx, hy, hz, cos_d, four_cos, o_faces_h);
      coat_f = terms.f, coat_pdf = terms.pdf;
    }
    // f where cos(theta_i) cos(theta_o) does not underflow (above_horizon, core/vec.h)
    const auto formed = hn::And(above, iz * oz > zero);
    for (int c = 0; c < 3; ++c) hn::StoreU(hn::IfThenElseZero(formed, body[c] + fresnel[c] * specular + coat_f), d, out[c] + k);
    const V lobe_pdf = hn::IfThenElseZero(o_faces_h, lanes::divide(d, dh, (one + lambda_o) * hn::Set(d, 4.0) * oz));
    hn::StoreU(hn::IfThenElseZero(above, lanes::mixture_density(d, model.weights, coat, lobe_pdf, coat_pdf, iz)), d, batch.pdf.data() + k);
  }
}

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace facetfit
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "model/parametric.h"
#include "model/proposal.h"
#include "render/simd_dispatch.h"
namespace facetfit {

const ParametricBrdf* ggx_drawn_by_itself(const LanesInput& in) {
  const auto* lobe = dynamic_cast<const ParametricBrdf*>(&in.brdf);
  const auto* ggx = dynamic_cast<const GgxProposal*>(in.proposal);
  if (lobe && ggx && in.lobe_weight > 0.0 && lobe->ndf().type == NdfType::ggx && lobe->ndf().alpha_x == ggx->alpha() &&
      lobe->ndf().alpha_y == ggx->alpha())
    return lobe;
  return nullptr;
}

std::optional<GgxLanes> GgxLanes::recognise(const LanesInput& in) {
  const ParametricBrdf* lobe = ggx_drawn_by_itself(in);
  if (!lobe) return std::nullopt;
  // The kernels hold one coat for f and density alike.
  const ProposalParts& parts = static_cast<const GgxProposal*>(in.proposal)->parts();
  if (parts.coat.alpha != lobe->coat().alpha || parts.coat.f0 != lobe->coat().f0) return std::nullopt;
  GgxLanes lanes;
  GgxBatchModel& m = lanes.model;
  m.alpha = lobe->ndf().alpha_x;
  m.smith = lobe->smith();
  m.curve = lobe->curve() ? lobe->curve()->value.data() : nullptr;
  m.f82_tint = lobe->f82_tint();
  m.body = lobe->body();
  m.coat = lobe->coat();
  m.weights = {in.lobe_weight, parts.lobe, parts.body, parts.coat.present() ? parts.coat_weight() : 0.0};
  return lanes;
}

void eval_ggx_batch(const GgxBatchModel& model, EvaluationBatch& batch, SimdTarget target) {
  FACETFIT_DISPATCH(target, EvalGgxBatch, model, batch);
}

void sample_ggx_batch(const GgxBatchModel& model, SampleBatch& batch, SimdTarget target) {
  FACETFIT_DISPATCH(target, SampleGgxBatch, model, batch);
}

}  // namespace facetfit
#endif
