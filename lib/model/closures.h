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
//
// A lobe with a view exponent k follows the view (view_aligned()): its x axis lies along the azimuth of o, and
// its alpha across the view grows as the view grazes, alpha_y / cos(theta_o)^k (at most 1, as renderers clamp a
// closure's roughness). A film with a clear top (vinyl wrap, lacquer) reflects a highlight wider across the
// plane of incidence than along it, the more so the more the view grazes (1.3x at theta_d 10 degrees, 1.7x at
// 28, 4x at 45 on a colour-shifting vinyl); a lobe of D(theta_h) alone cannot (docs/extraction.md). A shader
// builds the same frame from its view vector (osl/facetfit_material.osl).
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
  double view_exponent = 0.0;  // k: 0 for a lobe along the tangent's axes

  bool view_aligned() const { return view_exponent != 0.0; }
  // The distribution seen from a view at cos theta_o: for a view-aligned lobe, along the axes of
  // TurnedFrame::of_azimuth(o).
  Ndf ndf(double cos_o = 1.0) const;
  Rgb fresnel_at(double cos_d) const;
};

// alpha / cos_o^k clamped to [alpha, 1] for k >= 0 (to (0, 1] for k < 0): the alpha across the view.
double alpha_across_view(double alpha, double k, double cos_o);

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
  // (x, y) along its own axes, and the axes turned by `rotation` radians more from the tangent; a
  // view-aligned lobe, whose axes are the view's, has both alphas scaled by sqrt(x y) and is not turned.
  Closures stretched(double x, double y, double rotation) const;
};

// Evaluates Closures as the renderer's closures do. Thread-safe.
class ClosureBrdf final : public Brdf {
 public:
  explicit ClosureBrdf(Closures closures);
  std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const override;
  const Closures& closures() const { return closures_; }

 private:
  std::vector<TurnedFrame> axes_;  // of each lobe along the tangent
  Closures closures_;
};

// Samples the closures as a renderer samples a sum of closures: u1 picks a lobe, the body or the coat with
// probabilities by albedo (a lobe's weight times the luminance of its F at 60 degrees, at least 0.05; the body's
// luminance; the coat's f0, at least 0.1) and is rescaled within it; a lobe draws the visible normals of
// the lobe seen from o in its own frame (GGX's in closed form; an older LUT's Beckmann lobe, those of the
// isotropic lobe of the same area, tabulated), the body the cosine, the coat its GGX visible normals. pdf()
// is the mixture's.
class ClosureProposal final : public Proposal {
 public:
  explicit ClosureProposal(const Closures& closures);
  std::optional<Vec3> sample_direction(const Vec3& o, double u1, double u2) const override;
  double pdf(const Vec3& o, const Vec3& i) const override;

 private:
  struct Lobe {
    double probability = 0.0;
    ClosureLobe lobe;
    TurnedFrame axes;                          // of a lobe along the tangent
    std::shared_ptr<const Proposal> beckmann;  // a Beckmann lobe's tabulated visible normals
  };
  std::vector<Lobe> lobes_;
  double body_ = 0.0, coat_probability_ = 0.0;
  Coat coat_;
};

}  // namespace facetfit
