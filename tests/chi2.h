// Pearson's chi-square goodness-of-fit test of a sampler against its pdf, as Mitsuba tests its BSDFs.
#pragma once

#include <cmath>
#include <functional>
#include <optional>
#include <random>
#include <vector>

#include "core/vec.h"

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

// The test of a sampler of directions i against its density in the space of i: `n` draws of
// sample(u1, u2) (an optional direction) binned uniformly in cos(theta_i) (32 bins) and phi_i (`phi_bins`),
// the expected counts n times pdf(i) integrated 8 x 8 finer per bin, one more category for draws that
// fail or leave the hemisphere.
template <class Sample, class Pdf>
ChiSquareResult chi_square_in_directions(const Sample& sample, const Pdf& pdf, int n, unsigned seed, int phi_bins = 48) {
  constexpr int kCos = 32, kSub = 8;
  const std::size_t outside = std::size_t(kCos) * std::size_t(phi_bins);
  std::vector<double> observed(outside + 1, 0.0), expected(outside + 1, 0.0);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < n; ++k) {
    const std::optional<Vec3> i = sample(u(rng), u(rng));
    if (!i || i->z <= 0.0) {
      observed[outside] += 1;
      continue;
    }
    double phi = std::atan2(i->y, i->x);
    if (phi < 0) phi += 2 * kPi;
    observed[std::size_t(std::min(kCos - 1, int(i->z * kCos)) * phi_bins + std::min(phi_bins - 1, int(phi / (2 * kPi) * phi_bins)))] += 1;
  }
  double total = 0.0;
  for (int a = 0; a < kCos; ++a)
    for (int b = 0; b < phi_bins; ++b) {
      double sum = 0.0;
      const double dc = 1.0 / (kCos * kSub), dphi = 2 * kPi / (phi_bins * kSub);
      for (int p = 0; p < kSub; ++p)
        for (int q = 0; q < kSub; ++q) {
          const double c = (a * kSub + p + 0.5) * dc, s = std::sqrt(1 - c * c), phi = (b * kSub + q + 0.5) * dphi;
          sum += pdf(Vec3(s * std::cos(phi), s * std::sin(phi), c)) * dc * dphi;
        }
      expected[std::size_t(a * phi_bins + b)] = sum * n;
      total += sum;
    }
  expected[outside] = std::max(0.0, (1.0 - total) * n);
  return chi_square(observed, expected);
}

}  // namespace facetfit::test
