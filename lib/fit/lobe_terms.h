// One microfacet lobe's terms with their derivatives, for the fits' hand-written Jacobians
// (fit/parametric_fit.cpp, fit/closure_fit.cpp): D, Smith's Lambda and G2 of the GGX and Beckmann
// families with d/dalpha, and the F82-tint Fresnel with d/df0 and d/df82.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/vec.h"
#include "model/fresnel.h"
#include "model/ndf.h"
#include "model/smith.h"

namespace facetfit::lobe_terms {

// A value and its derivative with respect to alpha.
struct WithSlope {
  double value = 0.0, slope = 0.0;
};

// Smith's Lambda of the two families at cos(theta) = c, and d/dalpha.
inline WithSlope lambda_of(NdfType type, double alpha, double c) {
  const double s2 = std::max(0.0, 1.0 - c * c);
  if (s2 <= 0.0) return {};
  if (type == NdfType::ggx) {
    // Lambda = (sqrt(1 + alpha^2 tan^2) - 1) / 2.
    const double q = s2 / (c * c), root = std::sqrt(1.0 + alpha * alpha * q);
    return {0.5 * (root - 1.0), 0.5 * alpha * q / root};
  }
  // Beckmann, x = cot(theta) / alpha: Lambda = (erf(x) - 1) / 2 + exp(-x^2) / (2 x sqrt(pi)),
  // dLambda/dalpha = exp(-x^2) / (2 sqrt(pi) x alpha).
  const double s = std::sqrt(s2), x = c / (alpha * s), e = std::exp(-x * x);
  constexpr double kSqrtPi = 1.7724538509055160273;
  return {0.5 * (std::erf(x) - 1.0) + e / (2.0 * kSqrtPi * x), e / (2.0 * kSqrtPi * x * alpha)};
}

// D of the two families at cos(theta_h) = c, and d/dalpha.
inline WithSlope ndf_of(NdfType type, double alpha, double c) {
  const double c2 = c * c, t2 = (1.0 - c2) / c2, a2 = alpha * alpha, c4 = c2 * c2;
  if (type == NdfType::ggx) {
    // D = a2 / (pi c^4 (a2 + t2)^2); dD/da2 = (t2 - a2) / (pi c^4 (a2 + t2)^3).
    const double den = a2 + t2, d = a2 / (kPi * c4 * den * den);
    return {d, 2.0 * alpha * (t2 - a2) / (kPi * c4 * den * den * den)};
  }
  // D = exp(-t2 / a2) / (pi a2 c^4); dD/da2 = D (t2 / a2 - 1) / a2.
  const double d = std::exp(-t2 / a2) / (kPi * a2 * c4);
  return {d, 2.0 * alpha * d * (t2 / a2 - 1.0) / a2};
}

// G2 of Lambda_i, Lambda_o (smith_g2), and d/dalpha through both.
inline WithSlope g2_of(Smith smith, const WithSlope& li, const WithSlope& lo) {
  switch (smith) {
    case Smith::masking: {
      const double g = smith_g2(smith, lo.value, li.value);
      return {g, -g * g * (li.value > lo.value ? li : lo).slope};
    }
    case Smith::correlated: {
      const double g = smith_g2(smith, lo.value, li.value);
      return {g, -g * g * (li.slope + lo.slope)};
    }
    case Smith::separable: {
      // G1(i) G1(o), each needed for the derivative.
      const double gi = 1.0 / (1.0 + li.value), go = 1.0 / (1.0 + lo.value);
      return {gi * go, -gi * go * (gi * li.slope + go * lo.slope)};
    }
  }
  return {};
}

// 1 - Schlick's weight (1 - mu)^5: d Schlick(f0, mu) / d f0.
inline double schlick_slope(double mu) { return 1.0 - fresnel_formulas::schlick_weight(ScalarOps{}, mu); }

// mu (1 - mu)^6: the shape of the F82-tint correction, multiplied as ((1 - mu)^3)^2, not as the renderer's
// ((1 - mu)^2)^3 (fresnel_formulas::f82_basis): the fits were made with this rounding, and the other moves
// the bits of two of the fourteen RGL bakes.
inline double f82_basis(double mu) {
  const double m = 1.0 - mu, m3 = m * m * m;
  return mu * m3 * m3;
}

// F82-tint as Schlick less a multiple of mu (1 - mu)^6,
//   F = Schlick(f0, mu) - a mu (1 - mu)^6 / b82,  a = Schlick(f0, 1/7) - f82,  b82 = mu (1 - mu)^6 at 1/7,
// so that F(1/7) = f82: a / b82 and its derivatives in f0 and f82.
struct F82Shift {
  double value = 0.0, d_f0 = 0.0, d_f82 = 0.0;
};
inline F82Shift f82_shift(double f0, double f82) {
  constexpr double kMu82 = 1.0 / 7.0;
  const double b82 = f82_basis(kMu82), schlick82 = 1.0 - schlick_slope(kMu82);
  return {(f0 * (1.0 - schlick82) + schlick82 - f82) / b82, (1.0 - schlick82) / b82, -1.0 / b82};
}

// One channel's Fresnel in the fits' forms and its derivatives in f0 and f82: F82-tint (above) or, without
// `tint`, Schlick alone (f82 unused).
struct FresnelTerms {
  double value = 0.0, d_f0 = 0.0, d_f82 = 0.0;
};
inline FresnelTerms fresnel_terms(double f0, double f82, double mu, bool tint) {
  const double s_mu = schlick_slope(mu);
  FresnelTerms f{f0 * s_mu + (1.0 - s_mu), s_mu, 0.0};
  if (!tint) return f;
  const F82Shift a = f82_shift(f0, f82);
  const double basis = f82_basis(mu);
  f.value -= a.value * basis;
  f.d_f0 -= a.d_f0 * basis;
  f.d_f82 = -a.d_f82 * basis;
  return f;
}

// GGX D G2 / (4 cos_i cos_o), height-correlated, of alphas (ax, ay) along the axes of the frame o, i and
// h = normalize(o + i) are given in, and its derivatives in log ax and log ay:
//   D = 1 / (pi ax ay t^2), t = hx^2 / ax^2 + hy^2 / ay^2 + hz^2: d log D / d log ax = 4 hx^2 / (ax^2 t) - 1;
//   Lambda(v) = (sqrt(1 + q) - 1) / 2, q = (vx^2 ax^2 + vy^2 ay^2) / vz^2: d Lambda / d log ax = vx^2 ax^2 / (2 vz^2 sqrt(1 + q)).
struct AnisotropicLobeTerms {
  double value = 0.0, d_log_ax = 0.0, d_log_ay = 0.0;
};
inline AnisotropicLobeTerms ggx_anisotropic_terms(const Vec3& o, const Vec3& i, const Vec3& h, double ax, double ay) {
  const double ax2 = ax * ax, ay2 = ay * ay;
  const double hx = h.x * h.x / ax2, hy = h.y * h.y / ay2, t = hx + hy + h.z * h.z;
  const double d = 1.0 / (kPi * ax * ay * t * t);
  struct Lambda {
    double value = 0.0, d_x = 0.0, d_y = 0.0;
  };
  const auto lambda = [&](const Vec3& v) {
    const double x = v.x * v.x * ax2 / (v.z * v.z), y = v.y * v.y * ay2 / (v.z * v.z), root = std::sqrt(1.0 + x + y);
    return Lambda{0.5 * (root - 1.0), 0.5 * x / root, 0.5 * y / root};
  };
  const Lambda lo = lambda(o), li = lambda(i);
  const double g = 1.0 / (1.0 + lo.value + li.value), inv4 = 1.0 / (4.0 * i.z * o.z), value = d * g * inv4;
  return {value, value * (4.0 * hx / t - 1.0 - g * (lo.d_x + li.d_x)), value * (4.0 * hy / t - 1.0 - g * (lo.d_y + li.d_y))};
}

// The clear coat's term, Schlick(f0, mu) D G2 / (4 cos_i cos_o) of GGX `alpha` (height-correlated), at
// cos theta_h, cos theta_i, cos theta_o and mu = cos theta_d, and its derivatives in log alpha and f0.
struct CoatTerms {
  double value = 0.0, d_log_alpha = 0.0, d_f0 = 0.0;
};
inline CoatTerms coat_terms(double alpha, double f0, double ch, double ci, double co, double mu) {
  const double inv4 = 1.0 / (4.0 * ci * co), s_mu = schlick_slope(mu);
  const WithSlope d = ndf_of(NdfType::ggx, alpha, ch);
  const WithSlope g = g2_of(Smith::correlated, lambda_of(NdfType::ggx, alpha, ci), lambda_of(NdfType::ggx, alpha, co));
  const double f = f0 * s_mu + (1.0 - s_mu);  // Schlick(f0, mu)
  return {f * d.value * g.value * inv4, f * (d.slope * g.value + d.value * g.slope) * inv4 * alpha, s_mu * d.value * g.value * inv4};
}

}  // namespace facetfit::lobe_terms
