// Parametric roughness from the tabulated slope distribution.
//
// GGX: the marginal slope density is 1 / (2 alpha (1 + x~^2/alpha^2)^(3/2)), so E|x~| = alpha.
// Beckmann: the slopes are Gaussian with variance alpha^2 / 2 per axis, so alpha = sqrt(2 E[x~^2]).
#pragma once

#include <functional>

#include "fit/quadrature.h"
#include "model/tabulated_ndf.h"
#include "model/ndf.h"

namespace facetfit {

double alpha_ggx_from_moments(const TabulatedNdf& ndf, const Quadrature& quadrature);
double alpha_beckmann_from_moments(const TabulatedNdf& ndf, const Quadrature& quadrature);

// Relative L1 distance of two isotropic NDFs (functions of theta), weighted by the projected area:
// integral of |D_a - D_b| cos(theta) dw / integral of D_a cos(theta) dw.
double ndf_distance(const Quadrature& quadrature, const std::function<double(double)>& a,
                    const std::function<double(double)>& b);
// The same, of an analytic NDF against a tabulated one (the reference).
double ndf_distance(const Quadrature& quadrature, const TabulatedNdf& reference, const Ndf& candidate);

// The alpha of `type` whose NDF is nearest the tabulated one in ndf_distance, searched from `start`.
double refine_alpha(const Quadrature& quadrature, const TabulatedNdf& ndf, NdfType type, double start);

}  // namespace facetfit
