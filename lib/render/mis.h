// Multiple importance sampling of a light sample against a BRDF sample, as the integrator weighs them.
#pragma once

#include <limits>

namespace facetfit {

// cos w(p, q) / p for a sample of density p weighed against the other technique's density q at the same
// direction by the power heuristic w(p, q) = p^2 / (p^2 + q^2): cos p / (p^2 + q^2), one division. Where
// p^2 + q^2 underflows (densities below 1e-154) and p > 0, cos / (p + q (q / p)), the same without the
// squares (w itself would be 0 / 0); 0 where p is 0. The SIMD lanes (render/wavefront.cpp) compute the same.
inline double power_heuristic_factor(double cos, double p, double q) {
  if (!(p > 0.0)) return 0.0;
  const double sum = p * p + q * q;
  return sum >= std::numeric_limits<double>::min() ? cos * p / sum : cos / (p + q * (q / p));
}

}  // namespace facetfit
