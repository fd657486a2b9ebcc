// An isotropic NDF tabulated on a ThetaGrid, with its projected-area table sigma.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "model/theta_grid.h"
#include "model/ndf.h"

namespace facetfit {

struct TabulatedNdf {
  ThetaGrid grid;
  std::vector<double> ndf;    // D(theta_j) in 1/sr; integral of D cos(theta) dw = 1
  std::vector<double> sigma;  // sigma(theta_j) = integral of max(0, k.h) D(h) dw_h, k at theta_j

  // D at any theta: the spline through the nodes, clipped at zero where it undershoots past a peak.
  double D(double theta) const { return std::max(0.0, grid.interpolate(ndf, theta)); }
  // The slope distribution P22(x~, y~) = D cos^4(theta) at slope radius tan(theta).
  double slope_pdf(double theta) const {
    const double c = std::cos(theta);
    return D(theta) * c * c * c * c;
  }
  double sigma_at(double theta) const { return grid.interpolate(sigma, theta); }
  // Smith masking G1 = cos(theta) / sigma(theta); 0 at and below the horizon.
  double g1(double cos_theta) const {
    if (cos_theta <= 0.0) return 0.0;
    const double s = sigma_at(std::acos(std::min(cos_theta, 1.0)));
    return s > cos_theta ? cos_theta / s : 1.0;
  }
};

// G1 tabulated for the inner loops that evaluate it millions of times (the fits' residuals, the
// renderer). What is tabulated is G1 / cos(theta) = 1 / sigma, which stays finite at the horizon (G1 itself
// falls to zero over cos(theta) in [0, alpha], linearly, and the fits divide it by cos(theta)), on a grid
// uniform in sqrt(cos(theta)) that crowds its nodes there. Linear between nodes; at 2048 nodes G1 is
// within 7.3e-5 of the spline's (relative, at any cos(theta) > 0) for GGX and Beckmann, alpha 0.005 to 1.5.
class G1Table {
 public:
  explicit G1Table(const TabulatedNdf& ndf, int size = 2048) : ratio_(std::size_t(size) + 1), scale_(size) {
    for (int m = 1; m <= size; ++m) {
      const double root = double(m) / size, c = root * root;
      ratio_[std::size_t(m)] = ndf.g1(c) / c;
    }
    const double horizon = ndf.sigma_at(0.5 * kPi);  // the limit 1 / sigma(pi/2)
    ratio_[0] = horizon > 0.0 ? 1.0 / horizon : ratio_[1];
  }
  double operator()(double cos_theta) const {
    if (!(cos_theta > 0.0)) return 0.0;
    const double x = std::sqrt(std::min(cos_theta, 1.0)) * scale_;
    const int m = int(x);
    if (m >= int(scale_)) return std::min(1.0, cos_theta * ratio_.back());
    const double t = x - m;
    return std::min(1.0, cos_theta * (ratio_[std::size_t(m)] + t * (ratio_[std::size_t(m) + 1] - ratio_[std::size_t(m)])));
  }

  // The table, for SIMD kernels that read it (render/tabulated_batch.h): size() + 1 entries.
  const double* ratios() const { return ratio_.data(); }
  int size() const { return int(scale_); }

 private:
  std::vector<double> ratio_;  // G1 / cos(theta) at cos(theta) = (m / size)^2
  double scale_;
};

// An analytic NDF on `grid`: its D and sigma at the nodes.
inline TabulatedNdf tabulate_ndf(const Ndf& ndf, const ThetaGrid& grid = ThetaGrid{90}) {
  TabulatedNdf t;
  t.grid = grid;
  for (int j = 0; j < grid.size(); ++j) {
    const Vec3 w = spherical_direction(grid.theta(j), 0.0);
    t.ndf.push_back(ndf.D(w));
    t.sigma.push_back(ndf.sigma(w));
  }
  return t;
}

}  // namespace facetfit
