// The tabulated microfacet model (a LUT: model/tabulated.h) over a batch, in SIMD lanes, as
// render/ggx_batch.h does for GGX: ShadingModel's sample_direction and eval (f(o, i) and the sampling
// density) with the lobe as BRDF and its visible slopes as proposal (model/visible_slopes.h), or the
// proposal alone (its draws and density), every term theirs in the same order, in single precision: the
// two agree to its rounding (tests/render/test_shading_lanes.cpp), but for a draw whose number falls within rounding of
// a boundary between cells. The arc cosines of f's grid lookups are render/lanes-inl.h's (Highway's
// polynomial); the proposal needs none.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "core/vec.h"
#include "model/coat.h"
#include "model/smith.h"
#include "render/merl_batch.h"
#include "render/shading_batch.h"
#include "render/simd_targets.h"

namespace facetfit {

class TabulatedMicrofacet;
class VisibleSlopeProposal;

// The lanes work in single precision, as a renderer's SIMD kernels commonly do: twice a double vector's
// lanes for the same instructions, in the costliest kernels of a LUT sphere's render (the tabulated lobe's
// draws and evaluations, docs/render-speed.md). Their tables are the model's, rounded to float.
struct TabulatedBatchModel {
  // f's tables, set where `f` (the BRDF is the lobe itself, unstretched): the theta grid
  // (model/theta_grid.h) and D at its resolution + 1 nodes, the four a grid interval's spline reads
  // together per interval; G1 / cos(theta) at cos(theta) = (m / g1_size)^2, m = 0..g1_size
  // (model/tabulated_ndf.h, G1Table); the Fresnel curve's 90 entries (r, g, b each); the body. Every table
  // has room for three more entries past its end (the lanes read four neighbours at once).
  bool f = false;
  int resolution = 0;
  const float* ndf = nullptr;
  const float* g1_ratios = nullptr;
  int g1_size = 0;
  Smith smith = Smith::correlated;
  const float* curve = nullptr;
  Rgb body{0.0};
  double body_exponent = 1.0;  // Minnaert's k (model/body.h)
  // The proposal's: its visible normals' tables (model/visible_slopes.h, VisibleSlopes), and the coat
  // (its f too where `f`).
  double scale = 1.0;
  const float* view_cdf = nullptr;
  const float* view_mass = nullptr;
  const std::int32_t* view_guide = nullptr;
  const float* side_cdf = nullptr;
  const float* side_mass = nullptr;
  const std::int32_t* side_guide = nullptr;
  Coat coat;
  ProposalWeights weights;
  // What the pointers above point into (shared by copies).
  std::shared_ptr<const std::vector<float>> values;
  std::shared_ptr<const std::vector<std::int32_t>> guides;

  // The lanes' model of `proposal` taken with weight lobe_weight, with f where `lobe` is the BRDF and
  // the lanes hold it (unstretched, the curve's 90 entries, the proposal's coat): the caller passes
  // with_f = f to eval_tabulated_batch.
  static TabulatedBatchModel of(const VisibleSlopeProposal& proposal, const TabulatedMicrofacet* lobe, double lobe_weight);
};

// Fills the batch's r, g, b and pdf for its padded_size() pairs; zero where o or i is below the horizon,
// and pdf zero for a vector of pairs none of which asks for it (EvaluationBatch::with_pdf).
// `target`: which SIMD code runs (render/simd_targets.h; the tests run each). Without `with_f` (or the
// model's `f`), pdf alone: the density of a proposal whose BRDF the lanes do not hold (a measured table's,
// sampled by its fitted LUT).
void eval_tabulated_batch(const TabulatedBatchModel& model, EvaluationBatch& batch, SimdTarget target = SimdTarget::best, bool with_f = true);
// Fills the batch's i and found for its padded_size() entries (ShadingModel::sample_direction).
void sample_tabulated_batch(const TabulatedBatchModel& model, SampleBatch& batch, SimdTarget target = SimdTarget::best);

// The lanes back-end (render/lanes.h) of a tabulated lobe's visible slopes (model/visible_slopes.h): a LUT's
// own, or those of a measured table's fitted LUT (or of a Beckmann lobe's tabulated NDF). f in the lanes
// where the BRDF is the LUT itself, or a MERL-layout table (render/merl_batch.h); else one pair at a time.
struct TabulatedLanes {
  TabulatedBatchModel model;
  std::optional<MerlBatchModel> merl;

  static std::optional<TabulatedLanes> recognise(const LanesInput& in);
  bool f_in_lanes() const { return model.f || merl; }
  void eval(EvaluationBatch& batch, const ShadingModel& shading) const;
  void sample(SampleBatch& batch) const { sample_tabulated_batch(model, batch); }
};

}  // namespace facetfit
