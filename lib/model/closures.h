// The fit as a renderer's own closures: a Lambertian body, up to three microfacet lobes and a clear coat,
// each exactly a closure that OSL renderers ship (docs/osl.md), summed:
//
//   f(o, i) = body / pi + sum_k w_k F_k(theta_d) D_k(h) G2_k(o, i) / (4 cos theta_i cos theta_o) + coat
//
// D_k the lobe's GGX (or, from an older LUT, Beckmann) distribution of (alpha_x, alpha_y) along axes turned
// by `angle` from the tangent, G2 height-correlated Smith (what Cycles evaluates), w_k the closure's weight.
// A lobe's Fresnel F_k is one of two closures' (mu = cos theta_d):
// - F82-tint (Cycles' `microfacet_f82_tint`; MaterialX's `generalized_schlick_bsdf` with color82):
//   Schlick(f0, mu) - a mu (1 - mu)^6, a such that F(1/7) = f82 (model/fresnel.h);
// - generalized Schlick (`generalized_schlick_bsdf` in Cycles and MaterialX, without color82):
//   f0 + (f90 - f0) (1 - mu)^exponent, whose exponent bends the colour over the middle angles, where
//   F82-tint is flat (a colour-shifting film's reflectance changes there).
// The coat is GGX with a grey Schlick Fresnel (model/coat.h): microfacet_f82_tint with a tint of 1.
#pragma once

#include <memory>
#include <utility>
#include <vector>

#include "core/brdf.h"
#include "core/frame.h"
#include "model/coat.h"
#include "model/fresnel.h"
#include "model/ndf.h"
#include "model/proposal.h"

namespace facetfit {

struct ClosureLobe {
  enum class Fresnel { f82_tint, schlick };
  NdfType type = NdfType::ggx;
  double alpha_x = 0.1, alpha_y = 0.1;
  double angle = 0.0;   // the x axis's azimuth from the tangent, radians
  double weight = 1.0;  // the closure's weight
  Fresnel fresnel = Fresnel::f82_tint;
  Rgb f0{0.04};
  Rgb f82{0.04};        // f82_tint: the reflectance at acos(1/7)
  Rgb f90{1.0};         // schlick: the reflectance at grazing, and the exponent
  double exponent = 5.0;

  Ndf ndf() const { return {type, alpha_x, alpha_y}; }
  Rgb fresnel_at(double cos_d) const;
};

// The lobe for a renderer without the F82 term (MaterialX's OSL generator drops color82): an F82-tint lobe
// becomes the generalized Schlick lobe whose curve is nearest, f0 kept, f90 per channel in [0, 1] and one
// exponent in [1, 16] by least squares over mu = cos theta_d uniform on [0, 1]. Other lobes are returned as
// they are.
ClosureLobe without_f82(const ClosureLobe& lobe);

struct Closures {
  static constexpr int kMaxLobes = 3;
  Rgb body{0.0};
  std::vector<ClosureLobe> lobes;  // none: no closure representation
  Coat coat;

  bool empty() const { return lobes.empty(); }
  // The artist's control (osl/facetfit_material.osl does the same): every lobe's alphas scaled by
  // (x, y) along its own axes, and the axes turned by `rotation` radians more from the tangent.
  Closures stretched(double x, double y, double rotation) const;
};

// Evaluates Closures as the renderer's closures do. Thread-safe.
class ClosureBrdf final : public Brdf {
 public:
  explicit ClosureBrdf(Closures closures);
  std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const override;
  const Closures& closures() const { return closures_; }

 private:
  struct Lobe {
    Ndf ndf;
    TurnedFrame axes;
  };
  Closures closures_;
  std::vector<Lobe> lobes_;
};

// Samples the closures as a renderer samples a sum of closures: u1 picks a lobe, the body or the coat with
// probabilities by albedo (a lobe's weight times the luminance of its F at 60 degrees, at least 0.05; the body's
// luminance; the coat's f0, at least 0.1) and is rescaled within it; a lobe draws the visible normals of
// the isotropic lobe of the same area (alpha = sqrt(alpha_x alpha_y): GGX in closed form, Beckmann
// tabulated), the body the cosine, the coat its GGX visible normals. pdf() is the mixture's.
class ClosureProposal final : public Proposal {
 public:
  explicit ClosureProposal(const Closures& closures);
  std::optional<Vec3> sample_direction(const Vec3& o, double u1, double u2) const override;
  double pdf(const Vec3& o, const Vec3& i) const override;

 private:
  std::vector<std::pair<double, std::shared_ptr<const Proposal>>> lobes_;  // probability, proposal
  double body_ = 0.0, coat_probability_ = 0.0;
  Coat coat_;
};

}  // namespace facetfit
