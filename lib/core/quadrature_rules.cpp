#include "core/quadrature_rules.h"

#include <cmath>

namespace facetfit {

void gauss_legendre(int n, std::vector<double>& x, std::vector<double>& w) {
  x.assign(std::size_t(n), 0.0);
  w.assign(std::size_t(n), 0.0);
  for (int i = 0; i < n; ++i) {
    // Newton on the Legendre polynomial P_n from the Chebyshev guess.
    double z = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = 0.0;
      for (int m = 1; m <= n; ++m) {
        const double p2 = p1;
        p1 = p0;
        p0 = ((2.0 * m - 1.0) * z * p1 - (m - 1.0) * p2) / m;
      }
      dp = n * (z * p0 - p1) / (z * z - 1.0);
      const double dz = p0 / dp;
      z -= dz;
      if (std::abs(dz) < 1e-15) break;
    }
    x[std::size_t(i)] = 0.5 * (1.0 - z);
    w[std::size_t(i)] = 1.0 / ((1.0 - z * z) * dp * dp);
  }
}

double positive_phi_integral(double a, double b) {
  if (a <= b) return 2.0 * kPi * b;
  return 2.0 * (std::sqrt(a * a - b * b) + b * std::acos(-b / a));
}

}  // namespace facetfit
