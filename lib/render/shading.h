// What the renderer shades with: a BRDF to evaluate, and a proposal to sample it.
//
// Every material, measured, tabulated or parametric, is sampled the same way: the visible normals of
// a microfacet proposal (model/proposal.h: the fitted LUT for a measured material, the material itself
// for a LUT, GGX's in closed form, Beckmann's NDF tabulated on the grid), mixed with cosine sampling so
// that whatever a single lobe does not explain (diffuse reflection) is still found. pdf() is that mixture.
// A tabulated lobe proposes through its visible slopes (model/visible_slopes.h: tables, no root to
// find), which the scene gives as a VisibleSlopeProposal; a stretched one (a roughness texture) through
// its own visible normals.
#pragma once

#include <memory>
#include <optional>

#include "core/brdf.h"
#include "model/ndf.h"
#include "model/proposal.h"
#include "render/lanes.h"
#include "render/shading_batch.h"

namespace facetfit {

class GgxProposal;
class ParametricBrdf;

class ShadingModel {
 public:
  // `proposal` may be null: cosine sampling alone (a Lambertian surface).
  ShadingModel(std::shared_ptr<const Brdf> brdf, std::shared_ptr<const Proposal> proposal);

  // f(o, i) in the local frame (missing measurements count as zero).
  Rgb f(const Vec3& o, const Vec3& i) const;
  double pdf(const Vec3& o, const Vec3& i) const;
  // Both at once, for o and i above the horizon: what a light sample weighted against this proposal needs.
  struct Evaluation {
    Rgb f;
    double pdf;
  };
  Evaluation eval(const Vec3& o, const Vec3& i) const;
  // The same, or f alone (density zero) unless `with_pdf`: a measured or tabulated proposal's density costs
  // a lookup of its own, which a light's direction does not need.
  Evaluation eval(const Vec3& o, const Vec3& i, bool with_pdf) const { return with_pdf ? eval(o, i) : Evaluation{f(o, i), 0.0}; }
  // eval() of every pair of the batch: in SIMD lanes where a back-end of render/lanes.h runs this model
  // (wholly, or the proposal's density with f one pair at a time), unless `simd` is false; one pair at a
  // time otherwise (the reference the lanes are tested against).
  void eval(EvaluationBatch& batch, bool simd = true) const;
  // The lanes back-end that runs this model, if it is a T (tests call its kernels with its model).
  template <class T>
  const T* lanes() const { return std::get_if<T>(&lanes_); }
  // Whether eval(EvaluationBatch&) and sample_directions() run in lanes (wholly or in part): a batch then
  // costs less than the pairs one by one.
  bool has_lanes() const { return !std::holds_alternative<std::monostate>(lanes_); }
  // Whether f itself runs in them too, not one pair at a time inside eval(EvaluationBatch&).
  bool f_in_lanes() const;

  using Sample = BrdfSample;
  std::optional<Sample> sample(const Vec3& o, double u1, double u2, double u3) const;
  // The direction sample() draws, for callers that evaluate in batches (sample() is none where its
  // density is zero).
  std::optional<Vec3> sample_direction(const Vec3& o, double u1, double u2, double u3) const;
  // sample_direction() of every entry of the batch, in SIMD lanes as eval(EvaluationBatch&) is.
  void sample_directions(SampleBatch& batch, bool simd = true) const;

  const Brdf& brdf() const { return *brdf_; }

 private:
  double mixture(const Vec3& i, double proposal_pdf) const;

  std::shared_ptr<const Brdf> brdf_;
  std::shared_ptr<const Proposal> proposal_;
  double lobe_weight_;  // probability of sampling the microfacet proposal
  // A GGX lobe sampled by its own visible normals (the ggx material): eval() computes the half vector, D
  // and Lambda(o) once for f and pdf. Null otherwise.
  const ParametricBrdf* ggx_brdf_ = nullptr;
  const GgxProposal* ggx_proposal_ = nullptr;
  LanesBackend lanes_;  // none (std::monostate) where no back-end runs this model
};

}  // namespace facetfit
