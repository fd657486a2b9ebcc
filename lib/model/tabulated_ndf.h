// An isotropic NDF tabulated on a ThetaGrid, with its projected-area table sigma.
#pragma once

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

// G1 tabulated on a uniform grid of cos(theta) for the inner loops that evaluate it millions of times.
class G1Table {
 public:
  explicit G1Table(const TabulatedNdf& ndf, int size = 1024) : values_(std::size_t(size) + 1) {
    for (int m = 0; m <= size; ++m) values_[std::size_t(m)] = ndf.g1(double(m) / size);
    scale_ = size;
  }
  double operator()(double cos_theta) const {
    const double x = cos_theta * scale_;
    if (x <= 0.0) return 0.0;
    const int m = int(x);
    if (m >= int(scale_)) return values_.back();
    const double t = x - m;
    return values_[std::size_t(m)] + t * (values_[std::size_t(m) + 1] - values_[std::size_t(m)]);
  }

 private:
  std::vector<double> values_;
  double scale_ = 1.0;
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
