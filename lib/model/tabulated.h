// The tabulated microfacet BRDF: the fitted tables evaluated, importance-sampled and given a pdf.
//
//   f(o, i) = f_body(o, i) + F(theta_d) D(h) G2(o, i) / (4 cos(theta_o) cos(theta_i)) + coat(o, i)
//
// with f_body Minnaert's body (model/body.h), D and sigma (hence G1 = cos / sigma) splines on the theta
// grid, F the RGB Fresnel curve and G2 the Smith model the fit was made with. sample() picks one of the
// three parts with probabilities set by their albedos (lobe_weight() and the rest), then draws: for the
// lobe the distribution of visible normals seen from o, D_o(h) = max(0, o.h) D(h) / sigma(o), reflecting o
// about h (docs/sampling.md); for the body the cosine; for the coat its GGX visible normals. pdf() is the
// mixture's.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "core/brdf.h"
#include "model/body.h"
#include "model/fresnel_curve.h"
#include "model/tabulated_ndf.h"
#include "model/coat.h"
#include "model/proposal.h"
#include "model/smith.h"
#include "model/stretch.h"

namespace facetfit {

// What a LUT holds for evaluation.
struct MicrofacetTables {
  TabulatedNdf ndf;
  Smith smith = Smith::correlated;
  FresnelCurve fresnel;
  Rgb body{0.0};  // the body's albedo at normal incidence (model/body.h)
  Coat coat;      // optional clear coat over it
  double body_exponent = 1.0;  // Minnaert's k (model/body.h): 1 is Lambert

  // The parts a proposal of this lobe draws from, weighted by F(0), the body and the coat (model/proposal.h).
  ProposalParts proposal_parts() const { return ProposalParts(fresnel.value[0], body, coat); }
};

// Tables for sampling visible normals. For each view slice s (theta_o at grid node s) and each u interval
// j of the theta_h axis, the probability that h falls in the interval: mass(s, j), and its running sum
// cdf(s, j) at node j (cdf(s, 0) = 0, cdf(s, R) = 1). Within an interval h is uniform in cos(theta_h).
struct VisibleNormalTables {
  int resolution = 0;
  std::vector<double> cdf;  // (R + 1) slices x (R + 1) nodes

  static VisibleNormalTables build(const TabulatedNdf& ndf);
  double cdf_at(int slice, int node) const { return cdf[std::size_t(slice) * (resolution + 1) + node]; }
  double mass(int slice, int interval) const { return cdf_at(slice, interval + 1) - cdf_at(slice, interval); }
  bool empty() const { return cdf.empty(); }
};

class TabulatedMicrofacet final : public Brdf, public Proposal {
 public:
  // Builds the sampling tables from the NDF.
  explicit TabulatedMicrofacet(MicrofacetTables tables);
  // Uses given sampling tables (from a LUT); empty tables make sample() and pdf() unavailable. A stretch
  // (model/stretch.h) reshapes the lobe, not the tables: D, masking, sampling and pdf follow it.
  TabulatedMicrofacet(MicrofacetTables tables, VisibleNormalTables sampling, Stretch stretch = {});

  std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const override;

  using Sample = BrdfSample;
  // Samples a light direction i for the view direction o from two uniform numbers in [0, 1) (u1 also
  // picks the part: its first lobe_weight() selects the lobe, the next body_weight() the body). nullopt
  // when the reflected direction falls below the horizon (the sample carries no energy), when o is at
  // or below the horizon, or when the model has no sampling tables.
  std::optional<Sample> sample(const Vec3& o, double u1, double u2) const;
  // The direction sample() would draw, without its pdf and weight (for callers that mix proposals).
  std::optional<Vec3> sample_direction(const Vec3& o, double u1, double u2) const override;
  // Density of sample() per steradian of i. Integrates over the upper hemisphere to the fraction of
  // samples that land there.
  double pdf(const Vec3& o, const Vec3& i) const override;

  double D(const Vec3& h) const;
  double g1(const Vec3& w) const;
  Rgb fresnel(double cos_d) const;
  // Density of the lobe's visible normals h seen from o, per steradian of h.
  double visible_normal_pdf(const Vec3& o, const Vec3& h) const;
  // Density of the lobe's part of sample() alone, per steradian of i.
  double lobe_pdf(const Vec3& o, const Vec3& i) const;
  // The probabilities of the three parts (they sum to 1): luminance of the body albedo, of F(0) for
  // the lobe and the coat's f0, the last two at least 0.1 so that a dark lobe is still found.
  double lobe_weight() const { return shared_->parts.lobe; }
  double body_weight() const { return shared_->parts.body; }
  double coat_weight() const { return shared_->parts.coat_weight(); }

  const MicrofacetTables& tables() const { return shared_->tables; }
  const VisibleNormalTables& sampling() const { return shared_->sampling; }
  const Stretch& stretch() const { return stretch_; }
  // cos(theta_j) at the grid's nodes; G1's table, which the SIMD kernels read (render/tabulated_batch.h).
  const std::vector<double>& cos_nodes() const { return shared_->cos_nodes; }
  const G1Table& g1_table() const { return *shared_->g1; }
  // The visible normals' density per unit cos(theta_h) in interval j of view slice s, mass(s, j) /
  // (cos_j - cos_{j+1}) (0 for an empty band), at s R + j, which pdf() reads; empty without sampling tables.
  const std::vector<double>& visible_density() const { return shared_->visible_density; }
  bool can_sample() const override { return !shared_->sampling.empty(); }

  // The same lobe under another stretch: shares the tables, so it is cheap enough to make per shading
  // point (a roughness texture, render/texture.h).
  TabulatedMicrofacet stretched(const Stretch& stretch) const;

 private:
  // What a stretch does not change, immutable and shared between copies.
  struct Shared {
    MicrofacetTables tables;
    VisibleNormalTables sampling;
    std::vector<double> cos_nodes;  // cos(theta_j)
    std::optional<G1Table> g1;      // G1 without an arc cosine and a spline per call
    std::vector<double> visible_density;
    ProposalParts parts;
  };
  std::shared_ptr<const Shared> shared_;
  Stretch stretch_;

  std::optional<Vec3> lobe_direction(const Vec3& o, double u1, double u2) const;
  // The measured (unstretched) lobe's visible normals: a draw, and the density per steradian of h.
  Vec3 measured_visible_normal(const Vec3& o, double u1, double u2) const;
  double measured_visible_normal_pdf(const Vec3& o, const Vec3& h) const;
};

}  // namespace facetfit
