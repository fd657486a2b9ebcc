// A parametric microfacet BRDF dressed with facetfit's fit: GGX or Beckmann alpha, either the measured
// RGB Fresnel curve or the F82-tint model from f0 and f82 (what renderers' closures take), a body and
// an optional coat.
#pragma once

#include "core/brdf.h"
#include "model/fresnel_curve.h"
#include "model/coat.h"
#include "model/fresnel.h"
#include "model/ndf.h"
#include "model/smith.h"

namespace facetfit {

class ParametricBrdf final : public Brdf {
 public:
  // `body`: a Lambertian albedo added under the lobe.
  ParametricBrdf(const Ndf& ndf, Smith smith, const FresnelCurve& curve, const Rgb& body = Rgb(0.0), const Coat& coat = {})
      : ndf_(ndf), smith_(smith), curve_(curve), body_(body), coat_(coat), use_curve_(true) {}
  ParametricBrdf(const Ndf& ndf, Smith smith, const Rgb& f0, const Rgb& f82, const Rgb& body = Rgb(0.0), const Coat& coat = {})
      : ndf_(ndf), smith_(smith), f82_tint_(f0, f82), body_(body), coat_(coat) {}

  std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const override;
  // f(o, i) for o and i above the horizon, from what a caller that also needs the lobe's density has
  // already computed: h = normalize(i + o), D(h) and Lambda(o).
  Rgb eval_with(const Vec3& o, const Vec3& i, const Vec3& h, double d, double lambda_o) const;
  const Ndf& ndf() const { return ndf_; }
  // Its terms, for the renderer's batch evaluation (render/ggx_batch.h): the Fresnel curve when the lobe
  // uses one (else null, and the F82-tint model holds).
  Smith smith() const { return smith_; }
  const FresnelCurve* curve() const { return use_curve_ ? &curve_ : nullptr; }
  const F82Tint& f82_tint() const { return f82_tint_; }
  const Rgb& body() const { return body_; }
  const Coat& coat() const { return coat_; }

 private:
  Ndf ndf_;
  Smith smith_;
  FresnelCurve curve_;
  F82Tint f82_tint_;
  Rgb body_{0.0};
  Coat coat_;
  bool use_curve_ = false;
};

}  // namespace facetfit
