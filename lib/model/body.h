// The body under the lobe: Minnaert's reciprocal generalisation of Lambert's law,
//
//   f_body(o, i) = body / pi * (k + 1) / 2 * (cos(theta_o) cos(theta_i))^(k - 1),   1 <= k <= kMaxBodyExponent
//
// k = 1 is Lambert. k > 1 darkens the body toward grazing angles on both sides, as where the light reaches
// a pigment and leaves it through an interface whose transmission falls toward grazing (a vinyl film's
// clear layer: satin_rosaline's measurement, docs/extraction.md; paper). `body` stays the directional
// albedo at normal incidence: int f_body cos(theta_i) d(omega_i) = body cos(theta_o)^(k - 1). k < 1 is
// left out: it brightens without bound at grazing angles.
#pragma once

#include <cmath>

namespace facetfit {

inline constexpr double kMaxBodyExponent = 3.0;

// b = (k + 1) / 2 x^(k - 1), x = cos_o cos_i, from ln x, and db/dk = x^(k - 1) (1/2 + (k + 1) / 2 ln x): what
// a fit of k needs (fit/refine.cpp holds ln x per measured pair).
struct MinnaertFactor {
  double value, d_exponent;
};
inline MinnaertFactor minnaert_factor_of_log(double k, double log_cosines) {
  const double power = k == 1.0 ? 1.0 : std::exp((k - 1.0) * log_cosines);
  return {0.5 * (k + 1.0) * power, power * (0.5 + 0.5 * (k + 1.0) * log_cosines)};
}

// (k + 1) / 2 (cos_o cos_i)^(k - 1): f_body = body / pi times this. 1 for a Lambertian body (k = 1).
inline double minnaert_factor(double k, double cos_o, double cos_i) {
  if (k == 1.0) return 1.0;
  const double x = cos_o * cos_i;
  return x > 0.0 ? minnaert_factor_of_log(k, std::log(x)).value : 0.0;
}

}  // namespace facetfit
