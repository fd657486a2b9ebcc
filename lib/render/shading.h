// What the renderer shades with: a BRDF to evaluate, and a proposal to sample it.
//
// Every material, measured, tabulated or parametric, is sampled the same way: the visible normals of
// a microfacet proposal (model/proposal.h: the fitted LUT for a measured material, the material itself
// for a LUT, GGX's in closed form, Beckmann's NDF tabulated on the grid), mixed with cosine sampling so
// that whatever a single lobe does not explain (diffuse reflection) is still found. pdf() is that mixture.
#pragma once

#include <memory>
#include <optional>

#include "core/brdf.h"
#include "model/ndf.h"
#include "model/proposal.h"

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

  using Sample = BrdfSample;
  std::optional<Sample> sample(const Vec3& o, double u1, double u2, double u3) const;

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
};

}  // namespace facetfit
