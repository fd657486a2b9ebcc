// Analytic BRDFs: the ground truth facetfit's accuracy is measured against.
#pragma once

#include <memory>
#include <vector>

#include "core/brdf.h"
#include "model/fresnel.h"
#include "model/ndf.h"
#include "model/smith.h"

namespace facetfit {

// f(o, i) = F(i.h) D(h) G2(o, i) / (4 cos(theta_i) cos(theta_o)).
class MicrofacetBrdf final : public Brdf {
 public:
  MicrofacetBrdf(Ndf ndf, Smith smith, Fresnel fresnel) : ndf_(ndf), smith_(smith), fresnel_(fresnel) {}
  std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const override;

  const Ndf& ndf() const { return ndf_; }
  Smith smith() const { return smith_; }
  const Fresnel& fresnel() const { return fresnel_; }

 private:
  Ndf ndf_;
  Smith smith_;
  Fresnel fresnel_;
};

class LambertBrdf final : public Brdf {
 public:
  // exponent 1: Lambert's law; another: Minnaert's, the albedo at normal incidence (model/body.h).
  explicit LambertBrdf(const Rgb& albedo, double exponent = 1.0) : albedo_(albedo), exponent_(exponent) {}
  std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const override;
  const Rgb& albedo() const { return albedo_; }
  double exponent() const { return exponent_; }

 private:
  Rgb albedo_;
  double exponent_;
};

// A layered look without the layering: the plain sum of its lobes.
class SumBrdf final : public Brdf {
 public:
  explicit SumBrdf(std::vector<std::shared_ptr<const Brdf>> lobes) : lobes_(std::move(lobes)) {}
  std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const override;

 private:
  std::vector<std::shared_ptr<const Brdf>> lobes_;
};

}  // namespace facetfit
