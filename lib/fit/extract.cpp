#include "fit/extract.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace facetfit {

namespace {

// Samples the kernel factor q(theta) on the grid nodes: a cubic Hermite spline in u through the
// measurements (centred-difference slopes; a zero slope at u = 0, where D is symmetric), extrapolated
// linearly in u past the last one. For masking and correlated q = f(k,k) cos(theta_k): it stays finite at
// grazing angles where f(k,k) itself grows like 1 / cos(theta_k). Linear interpolation between MERL's
// bins would cost a smooth material about 0.7% of alpha at any resolution but 90 (docs/accuracy.md).
}  // namespace

std::vector<double> kernel_factor(const Backscatter& back, const ThetaGrid& grid, Smith smith) {
  const bool times_cos = smith != Smith::separable;
  const std::size_t m = back.theta.size();
  // Few samples (a goniometric grid such as UTIA's six polar angles, 15 degrees apart): the spline runs
  // through the logarithm against theta, in which a lobe's fall over orders of magnitude is smooth and even
  // about the normal; through the values against u it overshoots between samples a lobe apart. On GGX and
  // Beckmann written as UTIA files the principal alphas come back within 1.9% down to alpha 0.2 this way,
  // against 7% through the values (tests/io/test_utia.cpp). Dense samples (MERL's 90) keep the values in u.
  std::vector<double> us(m), qs(m), slope(m);
  for (std::size_t t = 0; t < m; ++t) qs[t] = back.value[t] * (times_cos ? std::cos(back.theta[t]) : 1.0);
  const double peak = *std::max_element(qs.begin(), qs.end());
  if (!(peak > 0.0)) return std::vector<double>(std::size_t(grid.size()), 0.0);  // no signal: the caller says so
  const bool logarithmic = m < 16;
  const auto coordinate = [logarithmic](double theta) { return logarithmic ? theta : ThetaGrid::u_of_theta(theta); };
  for (std::size_t t = 0; t < m; ++t) {
    us[t] = coordinate(back.theta[t]);
    if (logarithmic) qs[t] = std::log(std::max(qs[t], 1e-12 * peak));
  }
  for (std::size_t t = 0; t < m; ++t) {
    const std::size_t a = t == 0 ? 0 : t - 1, b = std::min(t + 1, m - 1);
    slope[t] = (t == 0 && us[0] == 0.0) ? 0.0 : (qs[b] - qs[a]) / (us[b] - us[a]);
  }
  std::vector<double> q(static_cast<std::size_t>(grid.size()));
  std::size_t seg = 0;
  for (int j = 0; j < grid.size(); ++j) {
    const double u = coordinate(grid.theta(j));
    while (seg + 2 < m && us[seg + 1] < u) ++seg;
    double value;
    if (u <= us[0]) {
      value = qs[0];
    } else if (u >= us[m - 1]) {
      value = qs[m - 1] + (u - us[m - 1]) * (qs[m - 1] - qs[m - 2]) / (us[m - 1] - us[m - 2]);
    } else {
      const double h = us[seg + 1] - us[seg], t = (u - us[seg]) / h;
      const double t2 = t * t, t3 = t2 * t;
      value = (2 * t3 - 3 * t2 + 1) * qs[seg] + (t3 - 2 * t2 + t) * h * slope[seg] + (-2 * t3 + 3 * t2) * qs[seg + 1] +
              (t3 - t2) * h * slope[seg + 1];
    }
    q[std::size_t(j)] = logarithmic ? std::exp(value) : std::max(0.0, value);
  }
  return q;
}

namespace {

double dot(const double* a, const std::vector<double>& b) {
  double s = 0.0;
  for (std::size_t j = 0; j < b.size(); ++j) s += a[j] * b[j];
  return s;
}

}  // namespace

PowerIteration power_iterate(std::vector<double>& D, const std::vector<double>& q, const std::vector<double>& area_weight,
                             const ExtractOptions& options,
                             const std::function<void(bool, const std::vector<double>&, std::vector<double>&)>& apply) {
  PowerIteration out;
  const std::size_t n = D.size();
  // Normalizes y so that its projected area is one; returns that area (the eigenvalue estimate).
  const auto normalize = [&](std::vector<double>& y) {
    double s = 0.0;
    for (std::size_t c = 0; c < n; ++c) s += area_weight[c] * y[c];
    if (!(s > 0.0) || !std::isfinite(s)) return 0.0;
    for (double& v : y) v /= s;
    return s;
  };
  if (normalize(D) == 0.0) {
    out.problem = "no back-scattered signal (all-zero or missing measurements)";
    return out;
  }
  std::vector<double> y(n), sigma(n);
  for (out.iterations = 1; out.iterations <= options.max_iterations; ++out.iterations) {
    apply(options.smith == Smith::correlated, D, sigma);
    for (std::size_t c = 0; c < n; ++c) {
      const double s = std::max(0.0, sigma[c]);  // the spline can dip below zero between nodes: clip
      y[c] = 4.0 * q[c] * (options.smith == Smith::separable ? s * s : s);
    }
    out.eigenvalue = normalize(y);
    if (out.eigenvalue == 0.0) {
      out.problem = "the back-scattering operator maps the distribution to zero";
      return out;
    }
    double change = 0.0;
    for (std::size_t c = 0; c < n; ++c) change += area_weight[c] * std::abs(y[c] - D[c]);
    D.swap(y);
    out.residual = change;
    if (change <= options.tolerance) {
      out.converged = true;
      break;
    }
  }
  out.iterations = std::min(out.iterations, options.max_iterations);
  return out;
}

Extraction extract_ndf(const Backscatter& back, const Quadrature& quad, const ExtractOptions& options) {
  Extraction out;
  const ThetaGrid& grid = quad.grid();
  const int n = grid.size();
  out.ndf.grid = grid;
  out.ndf.ndf.assign(std::size_t(n), 0.0);
  out.ndf.sigma.assign(std::size_t(n), 0.0);
  if (back.theta.size() < 2) {
    out.problem = "fewer than two back-scattering measurements";
    return out;
  }
  const std::vector<double> q = kernel_factor(back, grid, options.smith);
  // Start from D proportional to f(k,k) cos^2(theta_k), the answer for sigma(k) = cos(theta_k).
  std::vector<double>& D = out.ndf.ndf;
  for (int k = 0; k < n; ++k) D[std::size_t(k)] = q[std::size_t(k)] * std::cos(grid.theta(k));
  static_cast<PowerIteration&>(out) =
      power_iterate(D, q, quad.projected_area(), options, [&](bool absolute, const std::vector<double>& d, std::vector<double>& sigma) {
        for (int k = 0; k < n; ++k) sigma[std::size_t(k)] = dot(absolute ? quad.absolute_row(k) : quad.positive_row(k), d);
      });
  if (!out.problem.empty()) return out;
  for (int k = 0; k < n; ++k) out.ndf.sigma[std::size_t(k)] = dot(quad.positive_row(k), D);
  return out;
}

}  // namespace facetfit
