// The tabulated microfacet model (a LUT: model/tabulated.h) over a batch, in SIMD lanes, as
// render/ggx_batch.h does for GGX: ShadingModel's sample_direction and eval (f(o, i) and the sampling
// density) with the model as BRDF and proposal, or as the proposal alone (its density), every term theirs
// in the same order, so the two agree to rounding (tests/test_render.cpp). The arc cosines of the grid
// lookups are render/lanes-inl.h's (Highway's polynomial); the azimuth's Newton steps take sines and
// cosines from a series of their own.
#pragma once

#include <cstdint>
#include <optional>

#include "core/vec.h"
#include "model/coat.h"
#include "model/smith.h"
#include "render/shading_batch.h"
#include "render/simd_targets.h"

namespace facetfit {

class TabulatedMicrofacet;

struct TabulatedBatchModel {
  // The theta grid (model/theta_grid.h) and its tables: D and cos(theta) at the resolution + 1 nodes, the
  // visible normals' running sums ((resolution + 1) view slices of resolution + 1 nodes).
  int resolution = 0;
  const double* ndf = nullptr;
  const double* cos_nodes = nullptr;
  const double* cdf = nullptr;
  // TabulatedMicrofacet::visible_density() and cdf_guide().
  const double* visible_density = nullptr;
  const std::int64_t* cdf_guide = nullptr;
  // G1 / cos(theta) at cos(theta) = (m / g1_size)^2, m = 0..g1_size (model/tabulated_ndf.h, G1Table).
  const double* g1_ratios = nullptr;
  int g1_size = 0;
  Smith smith = Smith::correlated;
  const Rgb* curve = nullptr;  // the Fresnel curve's 90 entries
  const double* azimuth_guess = nullptr;  // AzimuthGuess::values() (model/visible_azimuth.h)
  Rgb body{0.0};
  double body_exponent = 1.0;  // Minnaert's k (model/body.h)
  Coat coat;
  ProposalWeights weights;

  // The lanes' model of `lobe` as a proposal taken with weight lobe_weight; none where the kernels do not
  // hold it (a stretched lobe, or one without sampling tables).
  static std::optional<TabulatedBatchModel> of(const TabulatedMicrofacet& lobe, double lobe_weight);
};

// Fills the batch's r, g, b and pdf for its padded_size() pairs; zero where o or i is below the horizon,
// and pdf zero for a vector of pairs none of which asks for it (EvaluationBatch::with_pdf).
// `target`: which SIMD code runs (render/simd_targets.h; the tests run each). Without `with_f`, pdf alone: the
// density of a model the lobe only samples (a measured table's fitted LUT).
void eval_tabulated_batch(const TabulatedBatchModel& model, EvaluationBatch& batch, SimdTarget target = SimdTarget::best, bool with_f = true);
// Fills the batch's i and found for its padded_size() entries (ShadingModel::sample_direction).
void sample_tabulated_batch(const TabulatedBatchModel& model, SampleBatch& batch, SimdTarget target = SimdTarget::best);

}  // namespace facetfit
