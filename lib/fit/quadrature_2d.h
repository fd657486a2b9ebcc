// Quadrature of hemispherical integrals of an anisotropic D(theta, phi): the spline in u = sqrt(theta /
// (pi/2)) of the isotropic grid (fit/quadrature.h) times `phi_count` azimuthal bins, D constant in each.
//
// The back-scattering kernel max(0, k.h) = max(0, sin(theta_k) sin(theta) cos(phi_k - phi) + cos(theta_k)
// cos(theta)) depends on the azimuths only through their difference, so for each pair of theta nodes it is
// a circulant operator in phi: sigma(theta_k, .) = sum_j K_kj * D(theta_j, .), a circular convolution. It
// is applied as a product of spectra (FFTW): O(J^2 M) per application with J theta nodes and M bins,
// instead of the (J M)^2 of a dense matrix. Each K_kj is even in the azimuth difference, so its spectrum
// is real, and only M/2 + 1 frequencies are kept. Built once per (resolution, phi_count), shared by every
// material; the FFTW plans are made here (planning is not thread-safe), executed anywhere.
#pragma once

#include <memory>
#include <vector>

#include "fit/quadrature.h"

namespace facetfit {

class Quadrature2D {
 public:
  Quadrature2D(int resolution, int phi_count);
  ~Quadrature2D();
  Quadrature2D(const Quadrature2D&) = delete;
  Quadrature2D& operator=(const Quadrature2D&) = delete;

  const ThetaGrid& grid() const { return base_.grid(); }
  const Quadrature& base() const { return base_; }
  int size() const { return base_.size(); }  // theta nodes J
  int phi_count() const { return phi_count_; }  // azimuthal bins M, centred on phi_m = 2 pi m / M
  int frequencies() const { return phi_count_ / 2 + 1; }
  double phi(int m) const;

  // Spectrum of K_kj for the kernel max(0, k.h), and for |k.h| (the height-correlated one).
  const double* positive_spectrum(int k, int j) const { return positive_.data() + (std::size_t(k) * size() + j) * frequencies(); }
  const double* absolute_spectrum(int k, int j) const { return absolute_.data() + (std::size_t(k) * size() + j) * frequencies(); }

  // sigma (or its height-correlated counterpart) of D, both J x M, theta-major.
  void apply(bool absolute, const std::vector<double>& D, std::vector<double>& sigma) const;

  // Projected area: sum_jm area(j) D(j, m) / M = integral of D cos(theta) dw (area() is the isotropic
  // weight, which holds 2 pi for the azimuth).
  const std::vector<double>& area() const { return base_.projected_area(); }

  // E|x~ cos(psi) + y~ sin(psi)| (first) and E[(x~ cos(psi) + y~ sin(psi))^2] (second; the last theta
  // interval left out, as in the isotropic moments) of the slopes of D: the roughness along psi. The theta
  // weights are the isotropic moments' (fit/quadrature.h), their azimuthal factor taken bin by bin.
  double abs_slope_moment(const std::vector<double>& D, double psi) const;
  double sq_slope_moment(const std::vector<double>& D, double psi) const;

  // Bytes held (spectra, weights and plans' buffers): the memory the bench reports.
  std::size_t bytes() const;

 private:
  Quadrature base_;
  int phi_count_;
  std::vector<double> positive_, absolute_;
  struct Plans;
  static std::unique_ptr<Plans> plan_transforms(int n, int m, int f);
  std::unique_ptr<Plans> plans_;
};

}  // namespace facetfit
