// Parametric fits on the whole measurement: body + one GGX or Beckmann lobe, in the metric of
// fit/measurement.h, from the moment estimates of the tabulated fit.
//
//   f(o, i) = body / pi + F(theta_d) D_alpha(h) G2_alpha(o, i) / (4 cos theta_i cos theta_o)
//
// Two Fresnel forms: `f82` (Hoffman's F82-tint from RGB f0 and f82, what renderers' closures take:
// the ggx and beckmann representations) and `schlick` (RGB f0 only: the classical baseline `lsq`, a
// Lambert + GGX + Schlick fit as users fit measured data today).
#pragma once

#include <string>

#include "fit/extract_2d.h"
#include "fit/measurement.h"
#include "model/coat.h"
#include "model/ndf.h"
#include "model/smith.h"

namespace facetfit {

struct ParametricFit {
  enum class FresnelForm { f82, schlick };
  NdfType type = NdfType::ggx;
  FresnelForm fresnel = FresnelForm::f82;
  double alpha = 0.0;
  Rgb body{0.0};
  Rgb f0{0.0}, f82{0.0};  // f82 = Schlick(f0, 1/7) for the schlick form
  Coat coat;              // fitted when the start has one (present()), else none
  double error = 0.0;     // measurement_error of the fit
};

// Least squares on `bins` from the start values (alpha > 0; body, f0, f82 in [0, 1]); with a coat in
// the start, the coat's alpha and f0 too. The fit's error is measured on `error_bins`.
ParametricFit fit_parametric(const MeasuredBins& bins, const MeasuredBins& error_bins, Smith smith,
                             const ParametricFit& start, int max_iterations = 50);

// The largest relative difference, over `bins`, between the hand-written derivatives of the fit's
// residuals and central differences, at the parameters of `fit` (with its coat if it has one): the
// check of fit_parametric's Jacobian (tests/fit/test_refine.cpp).
double parametric_jacobian_error(const MeasuredBins& bins, Smith smith, const ParametricFit& fit);

// The fit's distance from the measurement (measurement_error of its BRDF).
double parametric_error(const MeasuredBins& bins, Smith smith, const ParametricFit& fit);

// An anisotropic lobe with a body, fitted on an anisotropic source's measured pairs or lattice
// (fit/measurement.h, anisotropic_bins; io/half_diff_lattice.h):
//   f(o, i) = body / pi + F(theta_d) D(h') G2(o', i') / (4 cos theta_i cos theta_o),
// primes the directions in the frame whose x axis lies at `alpha.angle`, D the family's (alpha_x, alpha_y)
// distribution, F the F82-tint model (the form an anisotropic closure takes).
struct AnisotropicParametricFit {
  NdfType type = NdfType::ggx;
  AnisotropicAlpha alpha;  // alpha_x >= alpha_y, angle in (-pi/2, pi/2]
  Rgb body{0.0}, f0{0.0}, f82{0.0};
  double error = 0.0;  // measurement_error of the fit
};

// Least squares in the metric of fit/measurement.h from `start` (its principal alphas > 0; body, f0, f82
// in [0, 1]); the shape's derivatives by central differences. The error is measured on `error_bins`.
AnisotropicParametricFit fit_parametric_anisotropic(const MeasuredBins& bins, const MeasuredBins& error_bins, Smith smith,
                                                    const AnisotropicParametricFit& start, int max_iterations = 50);

// The fit's distance from the measurement (measurement_error of its BRDF).
double parametric_error(const MeasuredBins& bins, Smith smith, const AnisotropicParametricFit& fit);

}  // namespace facetfit
