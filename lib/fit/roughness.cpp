#include "fit/roughness.h"

#include <cmath>

namespace facetfit {

namespace {

double weighted_sum(const std::vector<double>& weights, const std::vector<double>& values) {
  double s = 0.0;
  for (std::size_t j = 0; j < weights.size(); ++j) s += weights[j] * values[j];
  return s;
}

}  // namespace

double alpha_ggx_from_moments(const TabulatedNdf& ndf, const Quadrature& quad) {
  return weighted_sum(quad.abs_slope_moment(), ndf.ndf);
}

double alpha_beckmann_from_moments(const TabulatedNdf& ndf, const Quadrature& quad) {
  return std::sqrt(2.0 * std::max(0.0, weighted_sum(quad.sq_slope_moment(), ndf.ndf)));
}

double ndf_distance(const Quadrature& quad, const std::function<double(double)>& a,
                    const std::function<double(double)>& b) {
  double diff = 0.0, norm = 0.0;
  for (const Quadrature::Node& node : quad.nodes()) {
    const double w = std::cos(node.theta) * std::sin(node.theta) * node.weight;  // 2 pi cancels
    const double da = a(node.theta);
    diff += std::abs(da - b(node.theta)) * w;
    norm += std::abs(da) * w;
  }
  return norm > 0.0 ? diff / norm : 0.0;
}

double ndf_distance(const Quadrature& quad, const TabulatedNdf& reference, const Ndf& candidate) {
  return ndf_distance(
      quad, [&](double theta) { return reference.D(theta); },
      [&](double theta) { return candidate.D(spherical_direction(theta, 0.0)); });
}

double refine_alpha(const Quadrature& quad, const TabulatedNdf& ndf, NdfType type, double start) {
  if (!(start > 0.0) || !std::isfinite(start)) return start;
  const auto cost = [&](double log_alpha) { return ndf_distance(quad, ndf, Ndf::isotropic(type, std::exp(log_alpha))); };
  // Golden-section search on log(alpha) within a factor of four of the moment estimate.
  const double golden = 0.5 * (std::sqrt(5.0) - 1.0);
  double lo = std::log(start) - std::log(4.0), hi = std::log(start) + std::log(4.0);
  double x1 = hi - golden * (hi - lo), x2 = lo + golden * (hi - lo);
  double c1 = cost(x1), c2 = cost(x2);
  while (hi - lo > 1e-5) {
    if (c1 < c2) {
      hi = x2;
      x2 = x1;
      c2 = c1;
      x1 = hi - golden * (hi - lo);
      c1 = cost(x1);
    } else {
      lo = x1;
      x1 = x2;
      c1 = c2;
      x2 = lo + golden * (hi - lo);
      c2 = cost(x2);
    }
  }
  return std::exp(0.5 * (lo + hi));
}

}  // namespace facetfit
