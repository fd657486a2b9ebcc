// The GGX material's sampling, f(o, i) and sampling density over a batch, in SIMD lanes (Google Highway,
// the widest target the CPU has, chosen at run time). The same model as ShadingModel's sample_direction
// and eval with a ParametricBrdf and a GgxProposal (render/shading.h): every term is theirs, in the same
// order, so the two agree to rounding (tests/render/test_shading_lanes.cpp).
#pragma once

#include <cstddef>
#include <optional>

#include "core/vec.h"
#include "model/coat.h"
#include "model/fresnel.h"
#include "model/smith.h"
#include "render/shading_batch.h"
#include "render/simd_targets.h"

namespace facetfit {

struct GgxBatchModel {
  double alpha = 0.5;  // the lobe's NDF (isotropic) and its visible normals
  Smith smith = Smith::correlated;
  // Fresnel: the tabulated curve (90 RGB entries, one per degree of theta_d) when not null, else F82-tint
  // Schlick(f0, mu) - a mu (1 - mu)^6, clamped at zero.
  const Rgb* curve = nullptr;
  F82Tint f82_tint;
  Rgb body{0.0};  // Lambertian albedo
  Coat coat;
  ProposalWeights weights;
};

// Fills the batch's r, g, b and pdf for its padded_size() pairs; zero where o or i is below the horizon.
// `target`: which SIMD code runs (render/simd_targets.h; the tests run each).
void eval_ggx_batch(const GgxBatchModel& model, EvaluationBatch& batch, SimdTarget target = SimdTarget::best);
// Fills the batch's i and found for its padded_size() entries.
void sample_ggx_batch(const GgxBatchModel& model, SampleBatch& batch, SimdTarget target = SimdTarget::best);

class ParametricBrdf;

// The GGX lobe of `in` when its proposal is the lobe's own visible normals (GgxProposal of the same alpha):
// f and density then share the half vector, D and Lambda, in the lanes and in ShadingModel's scalar path.
// Null otherwise.
const ParametricBrdf* ggx_drawn_by_itself(const LanesInput& in);

// The lanes back-end (render/lanes.h) of such a lobe with the proposal's coat.
struct GgxLanes {
  GgxBatchModel model;

  static std::optional<GgxLanes> recognise(const LanesInput& in);
  bool f_in_lanes() const { return true; }
  void eval(EvaluationBatch& batch, const ShadingModel&) const { eval_ggx_batch(model, batch); }
  void sample(SampleBatch& batch) const { sample_ggx_batch(model, batch); }
};

}  // namespace facetfit
