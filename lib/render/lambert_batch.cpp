// Compiled once per SIMD target by Highway's foreach_target (this file includes itself), as
// render/ggx_batch.cpp.
#include "render/simd_targets.h"  // before any of Highway's headers
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "render/lambert_batch.cpp"
#include <hwy/foreach_target.h>  // before highway.h

#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

#include "render/lambert_batch.h"
#include "render/lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace facetfit {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using lanes::D;
using lanes::V;

void EvalLambertBatch(const Rgb& albedo, EvaluationBatch& batch) {
  const D d;
  const V zero = hn::Zero(d), inv_pi = hn::Set(d, kInvPi);
  const V f[3] = {hn::Set(d, albedo.r * kInvPi), hn::Set(d, albedo.g * kInvPi), hn::Set(d, albedo.b * kInvPi)};
  double* out[3] = {batch.r.data(), batch.g.data(), batch.b.data()};
  for (std::size_t k = 0; k < batch.padded_size(); k += hn::Lanes(d)) {
    const V iz = hn::LoadU(d, batch.iz.data() + k);
    const auto above = hn::And(iz > zero, hn::LoadU(d, batch.oz.data() + k) > zero);
    for (int c = 0; c < 3; ++c) hn::StoreU(hn::IfThenElseZero(above, f[c]), d, out[c] + k);
    hn::StoreU(hn::IfThenElseZero(above, iz * inv_pi), d, batch.pdf.data() + k);
  }
}

void SampleLambertBatch(SampleBatch& batch) {
  const D d;
  // Cosine sampling alone: no proposal, every draw past its weight of zero (ShadingModel::sample_direction).
  const ProposalWeights cosine_only{0.0, 1.0, 0.0, 0.0};
  lanes::sample_proposal(d, cosine_only, Coat{}, batch, false, [&](V, V, V, V, V, V, V) {
    const V zero = hn::Zero(d);
    return lanes::Direction{zero, zero, zero};
  });
}

// NOLINTNEXTLINE(google-readability-namespace-comments)
}  // namespace HWY_NAMESPACE
}  // namespace facetfit
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include "model/analytic.h"
#include "render/simd_dispatch.h"
namespace facetfit {

std::optional<LambertLanes> LambertLanes::recognise(const LanesInput& in) {
  const auto* lambert = dynamic_cast<const LambertBrdf*>(&in.brdf);
  if (!lambert || lambert->exponent() != 1.0 || in.lobe_weight != 0.0) return std::nullopt;
  return LambertLanes{lambert->albedo()};
}

void eval_lambert_batch(const Rgb& albedo, EvaluationBatch& batch, SimdTarget target) { FACETFIT_DISPATCH(target, EvalLambertBatch, albedo, batch); }

void sample_lambert_batch(SampleBatch& batch, SimdTarget target) { FACETFIT_DISPATCH(target, SampleLambertBatch, batch); }

}  // namespace facetfit
#endif
