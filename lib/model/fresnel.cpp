#include "model/fresnel.h"

#include <cmath>
#include <complex>

#include "model/fresnel_curve.h"

namespace facetfit {

Rgb fresnel_schlick(const Rgb& f0, double cos_d) {
  const ScalarOps op;
  return fresnel_formulas::schlick(op, f0, fresnel_formulas::schlick_weight(op, cos_d));
}

namespace {

// Unpolarized reflectance of a conductor, from the complex Snell law (pbrt-v4's FrComplex).
double conductor_channel(double eta, double k, double cos_i) {
  using C = std::complex<double>;
  cos_i = clamp(cos_i, 0.0, 1.0);
  const C n(eta, k);
  const double sin2_i = 1.0 - cos_i * cos_i;
  const C sin2_t = sin2_i / (n * n);
  const C cos_t = std::sqrt(C(1.0) - sin2_t);
  const C r_parl = (n * cos_i - cos_t) / (n * cos_i + cos_t);
  const C r_perp = (cos_i - n * cos_t) / (cos_i + n * cos_t);
  return 0.5 * (std::norm(r_parl) + std::norm(r_perp));
}

}  // namespace

Rgb fresnel_conductor(const Rgb& eta, const Rgb& k, double cos_d) {
  return {conductor_channel(eta.r, k.r, cos_d), conductor_channel(eta.g, k.g, cos_d),
          conductor_channel(eta.b, k.b, cos_d)};
}

double fresnel_dielectric(double eta, double cos_d) {
  cos_d = clamp(cos_d, 0.0, 1.0);
  const double sin2_t = (1.0 - cos_d * cos_d) / (eta * eta);
  if (sin2_t >= 1.0) return 1.0;
  const double cos_t = std::sqrt(1.0 - sin2_t);
  const double r_parl = (eta * cos_d - cos_t) / (eta * cos_d + cos_t);
  const double r_perp = (cos_d - eta * cos_t) / (cos_d + eta * cos_t);
  return 0.5 * (r_parl * r_parl + r_perp * r_perp);
}

F82Tint::F82Tint(const Rgb& normal_incidence, const Rgb& f82) : f0(normal_incidence) {
  constexpr double mu82 = 1.0 / 7.0;
  a = (fresnel_schlick(f0, mu82) - f82) / fresnel_formulas::f82_basis(ScalarOps{}, mu82);
}

Rgb F82Tint::eval(double cos_d) const {
  const ScalarOps op;
  const double mu = clamp(cos_d, 0.0, 1.0);
  const double w = fresnel_formulas::schlick_weight(op, mu), basis = fresnel_formulas::f82_basis(op, mu);
  return {fresnel_formulas::f82_tint(op, f0.r, a.r, w, basis), fresnel_formulas::f82_tint(op, f0.g, a.g, w, basis),
          fresnel_formulas::f82_tint(op, f0.b, a.b, w, basis)};
}

Rgb Fresnel::eval(double cos_d) const {
  switch (kind) {
    case Kind::one: return Rgb(1.0);
    case Kind::schlick: return fresnel_schlick(f0, cos_d);
    case Kind::conductor: return fresnel_conductor(eta, k, cos_d);
    case Kind::dielectric: return Rgb(fresnel_dielectric(eta.x, cos_d));
  }
  return Rgb(1.0);
}

Rgb FresnelCurve::eval(double theta_d) const {
  const double x = clamp(theta_d / (0.5 * kPi) * kSize, 0.0, double(kSize - 1));
  const int j = std::min(int(x), kSize - 2);
  const double t = x - j;
  return value[std::size_t(j)] * (1.0 - t) + value[std::size_t(j) + 1] * t;
}

}  // namespace facetfit
