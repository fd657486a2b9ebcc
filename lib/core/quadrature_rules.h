// One-dimensional quadrature rules and the closed-form azimuthal integral of the projected-area
// kernel: the numerical pieces that the extraction, the tabulated model and the RGL reader share.
#pragma once

#include <vector>

#include "core/vec.h"

namespace facetfit {

// Integral over phi in [0, 2 pi) of max(0, a cos(phi) + b), for a >= 0 and b >= 0: with
// a = sin(theta_k) sin(theta), b = cos(theta_k) cos(theta) it is the azimuthal part of the projected area
// of the facets at theta seen from theta_k. Closed form: 2 pi b if a <= b, else
// 2 (sqrt(a^2 - b^2) + b acos(-b / a)).
double positive_phi_integral(double a, double b);

// Gauss-Legendre nodes and weights on [0, 1].
void gauss_legendre(int n, std::vector<double>& x, std::vector<double>& w);

}  // namespace facetfit
