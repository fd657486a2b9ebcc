// Pearson's chi-square goodness-of-fit test of a sampler against its pdf, as Mitsuba tests its BSDFs.
#pragma once

#include <cmath>
#include <functional>
#include <vector>

namespace facetfit::test {

// Regularized upper incomplete gamma Q(a, x): series for x < a + 1, continued fraction otherwise.
inline double gamma_q(double a, double x) {
  if (x <= 0.0) return 1.0;
  const double log_prefix = -x + a * std::log(x) - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 10000 && std::abs(term) > 1e-15 * std::abs(sum); ++n) {
      term *= x / (a + n);
      sum += term;
    }
    return 1.0 - sum * std::exp(log_prefix);
  }
  // Lentz's continued fraction.
  double b = x + 1.0 - a, c = 1e300, d = 1.0 / b, h = d;
  for (int n = 1; n < 10000; ++n) {
    const double an = -n * (n - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::abs(c) < 1e-300) c = 1e-300;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-15) break;
  }
  return std::exp(log_prefix) * h;
}

struct ChiSquareResult {
  double statistic = 0.0;
  int dof = 0;
  double p_value = 1.0;
};

// Observed counts against expected counts (same binning); bins expecting fewer than 5 are pooled.
inline ChiSquareResult chi_square(const std::vector<double>& observed, const std::vector<double>& expected) {
  ChiSquareResult r;
  double pooled_obs = 0.0, pooled_exp = 0.0;
  int bins = 0;
  for (std::size_t k = 0; k < observed.size(); ++k) {
    if (expected[k] < 5.0) {
      pooled_obs += observed[k];
      pooled_exp += expected[k];
      continue;
    }
    r.statistic += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
    ++bins;
  }
  if (pooled_exp >= 5.0) {
    r.statistic += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
    ++bins;
  } else if (pooled_obs > 5.0 * std::max(pooled_exp, 1.0)) {
    r.statistic += 1e9;  // samples where the pdf says there can be almost none
  }
  r.dof = std::max(1, bins - 1);
  r.p_value = gamma_q(0.5 * r.dof, 0.5 * r.statistic);
  return r;
}

}  // namespace facetfit::test
