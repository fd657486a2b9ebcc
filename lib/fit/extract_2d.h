// Extraction of an anisotropic NDF D(theta, phi) by power iteration on the back-scattering equation:
// fit/extract.h with the azimuth kept. For the masking form,
//   F0 D(k) = 4 cos(theta_k) f(k, k) integral max(0, k.h) D(h) dw_h,
// now with k = (theta_k, phi_k) over the hemisphere; the integral is fit/quadrature_2d.h's circulant
// operator in phi (FFTs), so one iteration costs O(J^2 M), not a dense (J M)^2 matrix. Same Smith
// variants, convergence test and residual as the isotropic path; on an isotropic measurement every phi
// bin holds the isotropic answer.
//
// The roughness of the result: along any azimuth psi the projected slope x~ cos(psi) + y~ sin(psi) of a
// GGX (a bivariate Student-t) or Beckmann (Gaussian) distribution is that family's one-dimensional
// marginal with alpha(psi)^2 = a^T S a, a = (cos psi, sin psi), S = R diag(alpha_x^2, alpha_y^2) R^T.
// So alpha(psi) measured along 0, 45 and 90 degrees gives S, whose eigen-decomposition is the principal
// alphas and the angle (fit/roughness.h's estimates along each direction: E| . | for GGX, sqrt(2 E[.^2])
// for Beckmann).
#pragma once

#include <string>
#include <vector>

#include "core/brdf.h"
#include "fit/extract.h"
#include "fit/quadrature_2d.h"
#include "io/backscatter_lattice.h"

namespace facetfit {

// f(k, k) measured at the quadrature's azimuths phi_m (one slice per azimuthal bin, in order), each at
// polar angles of its own.
struct Backscatter2D {
  std::vector<Backscatter> slices;
};

// f(k, k) of a BRDF (e.g. an analytic anisotropic model) at MERL's theta_h bins and the quadrature's azimuths.
Backscatter2D backscatter_2d(const Brdf& brdf, const Quadrature2D& quadrature);
// f(k, k) measured at a lattice's nodes (a UTIA file's diagonal: UtiaBrdf::backscatter), linear in phi
// between its azimuths (the file's eval() would mix in nodes that are not back-scattering).
Backscatter2D backscatter_2d(const BackscatterLattice& lattice, const Quadrature2D& quadrature);

struct Extraction2D : PowerIteration {
  int phi_count = 0;
  std::vector<double> ndf;    // D(theta_j, phi_m), J x M theta-major, 1/sr; projected area 1
  std::vector<double> sigma;  // sigma(theta_j, phi_m)

  double D(int j, int m) const { return ndf[std::size_t(j) * phi_count + m]; }
};

Extraction2D extract_ndf_2d(const Backscatter2D& backscatter, const Quadrature2D& quadrature, const ExtractOptions& options);

// Principal roughness of a 2D NDF: alpha_x >= alpha_y along the axes at `angle` (radians in
// (-pi/2, pi/2], the x axis's azimuth).
struct AnisotropicAlpha {
  double alpha_x = 0.0, alpha_y = 0.0, angle = 0.0;
};
AnisotropicAlpha alpha_ggx_2d(const std::vector<double>& ndf, const Quadrature2D& quadrature);
AnisotropicAlpha alpha_beckmann_2d(const std::vector<double>& ndf, const Quadrature2D& quadrature);

}  // namespace facetfit
