// A Lambertian surface's f(o, i), density and cosine sampling over a batch, in SIMD lanes (Google Highway,
// as render/ggx_batch.h): ShadingModel's eval and sample_direction with a LambertBrdf and no proposal
// (render/shading.h), term for term. In lanes because, one pair at a time, a Lambertian sphere would render
// slower than a GGX one in lanes (docs/benchmarks.md, BM_RenderSphere).
#pragma once

#include <optional>

#include "core/vec.h"
#include "render/shading_batch.h"
#include "render/simd_targets.h"

namespace facetfit {

// Fills the batch's r, g, b (albedo / pi) and pdf (cos theta_i / pi) for its padded_size() pairs; zero
// where o or i is below the horizon. `target`: which SIMD code runs (render/simd_targets.h).
void eval_lambert_batch(const Rgb& albedo, EvaluationBatch& batch, SimdTarget target = SimdTarget::best);
// Fills the batch's i (cosine-weighted, model/warps-inl.h) and found for its
// padded_size() entries.
void sample_lambert_batch(SampleBatch& batch, SimdTarget target = SimdTarget::best);

// The lanes back-end (render/lanes.h) of a Lambertian surface (Lambert's law, not Minnaert's) sampled by
// the cosine alone.
struct LambertLanes {
  Rgb albedo;

  static std::optional<LambertLanes> recognise(const LanesInput& in);
  bool f_in_lanes() const { return true; }
  void eval(EvaluationBatch& batch, const ShadingModel&) const { eval_lambert_batch(albedo, batch); }
  void sample(SampleBatch& batch) const { sample_lambert_batch(batch); }
};

}  // namespace facetfit
