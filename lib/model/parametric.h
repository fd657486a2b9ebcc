// A parametric microfacet BRDF dressed with facetfit's fit: GGX or Beckmann alpha, and either the
// measured RGB Fresnel curve or the F82-tint model from f0 and f82 (what renderers' closures take).
#pragma once

#include "core/brdf.h"
#include "fit/fresnel_fit.h"
#include "model/ndf.h"
#include "model/smith.h"

namespace facetfit {

class ParametricBrdf final : public Brdf {
 public:
  ParametricBrdf(const Ndf& ndf, Smith smith, const FresnelCurve& curve) : ndf_(ndf), smith_(smith), curve_(curve), use_curve_(true) {}
  ParametricBrdf(const Ndf& ndf, Smith smith, const Rgb& f0, const Rgb& f82) : ndf_(ndf), smith_(smith), f0_(f0), f82_(f82) {}

  std::optional<Rgb> eval(const Vec3& i, const Vec3& o) const override;
  const Ndf& ndf() const { return ndf_; }

 private:
  Ndf ndf_;
  Smith smith_;
  FresnelCurve curve_;
  Rgb f0_{0.0}, f82_{0.0};
  bool use_curve_ = false;
};

}  // namespace facetfit
