#include "fit/extract_2d.h"

#include <cmath>

namespace facetfit {

Backscatter2D backscatter_2d(const Brdf& brdf, const Quadrature2D& quad) {
  Backscatter2D b;
  for (int m = 0; m < quad.phi_count(); ++m) {
    Backscatter slice;
    for (int i = 0; i < 90; ++i) {
      const double t = i / 90.0, theta = t * t * 0.5 * kPi;  // MERL's theta_h bins
      const Vec3 k = spherical_direction(theta, quad.phi(m));
      const auto f = brdf.eval(k, k);
      if (!f) continue;
      slice.theta.push_back(theta);
      slice.value.push_back(std::max(0.0, luminance(*f)));
    }
    b.slices.push_back(std::move(slice));
  }
  return b;
}

Backscatter2D backscatter_2d(const BackscatterLattice& lattice, const Quadrature2D& quad) {
  Backscatter2D b;
  for (int m = 0; m < quad.phi_count(); ++m) {
    const double x = quad.phi(m) / (2.0 * kPi) * lattice.azimuths;
    const int lo = std::min(int(x), lattice.azimuths - 1), hi = (lo + 1) % lattice.azimuths;
    const double t = x - lo;
    Backscatter slice;
    for (std::size_t p = 0; p < lattice.theta.size(); ++p) {
      const Rgb f = lattice.at(int(p), lo) * (1.0 - t) + lattice.at(int(p), hi) * t;
      slice.theta.push_back(lattice.theta[p]);
      slice.value.push_back(std::max(0.0, luminance(f)));
    }
    b.slices.push_back(std::move(slice));
  }
  return b;
}

Extraction2D extract_ndf_2d(const Backscatter2D& back, const Quadrature2D& quad, const ExtractOptions& options) {
  Extraction2D out;
  const int n = quad.size(), m = quad.phi_count();
  const std::size_t cells = std::size_t(n) * m;
  out.phi_count = m;
  out.ndf.assign(cells, 0.0);
  out.sigma.assign(cells, 0.0);
  if (back.slices.size() != std::size_t(m)) {
    out.problem = "back-scattering has " + std::to_string(back.slices.size()) + " azimuthal slices, the grid " + std::to_string(m);
    return out;
  }
  // The kernel factor q(theta_j, phi_m), slice by slice on the theta grid (fit/extract.h).
  std::vector<double> q(cells);
  for (int p = 0; p < m; ++p) {
    if (back.slices[std::size_t(p)].theta.size() < 2) {
      out.problem = "fewer than two back-scattering measurements at azimuth " + std::to_string(p);
      return out;
    }
    const std::vector<double> column = kernel_factor(back.slices[std::size_t(p)], quad.grid(), options.smith);
    for (int j = 0; j < n; ++j) q[std::size_t(j) * m + p] = column[std::size_t(j)];
  }
  std::vector<double>& D = out.ndf;
  std::vector<double> area_weight(cells);
  for (int j = 0; j < n; ++j)
    for (int p = 0; p < m; ++p) {
      D[std::size_t(j) * m + p] = q[std::size_t(j) * m + p] * std::cos(quad.grid().theta(j));
      area_weight[std::size_t(j) * m + p] = quad.area()[std::size_t(j)] / m;
    }
  static_cast<PowerIteration&>(out) = power_iterate(D, q, area_weight, options, [&](bool absolute, const std::vector<double>& d, std::vector<double>& sigma) {
    quad.apply(absolute, d, sigma);
  });
  if (!out.problem.empty()) return out;
  quad.apply(false, D, out.sigma);
  return out;
}

namespace {

// The principal axes of alpha(psi)^2 = a^T S a from its values along 0, 45 and 90 degrees.
AnisotropicAlpha principal(double along_0, double along_45, double along_90) {
  const double sxx = along_0, syy = along_90, sxy = along_45 - 0.5 * (sxx + syy);
  const double mean = 0.5 * (sxx + syy), radius = std::hypot(0.5 * (sxx - syy), sxy);
  AnisotropicAlpha a;
  a.alpha_x = std::sqrt(std::max(0.0, mean + radius));
  a.alpha_y = std::sqrt(std::max(0.0, mean - radius));
  a.angle = radius > 0.0 ? 0.5 * std::atan2(2.0 * sxy, sxx - syy) : 0.0;
  return a;
}

}  // namespace

AnisotropicAlpha alpha_ggx_2d(const std::vector<double>& ndf, const Quadrature2D& quad) {
  const auto a2 = [&](double psi) {
    const double e = quad.abs_slope_moment(ndf, psi);  // E|projected slope| = alpha(psi)
    return e * e;
  };
  return principal(a2(0.0), a2(0.25 * kPi), a2(0.5 * kPi));
}

AnisotropicAlpha alpha_beckmann_2d(const std::vector<double>& ndf, const Quadrature2D& quad) {
  const auto a2 = [&](double psi) { return 2.0 * std::max(0.0, quad.sq_slope_moment(ndf, psi)); };
  return principal(a2(0.0), a2(0.25 * kPi), a2(0.5 * kPi));
}

}  // namespace facetfit
