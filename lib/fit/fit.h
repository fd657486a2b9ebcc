// The whole fit of one measured isotropic material: NDF, sigma, RGB Fresnel, GGX and Beckmann alpha.
#pragma once

#include <string>

#include "fit/extract.h"
#include "fit/fresnel_fit.h"
#include "fit/quadrature.h"
#include "io/merl.h"

namespace facetfit {

struct FitOptions {
  int resolution = 90;  // intervals of the u grid; R + 1 nodes
  Smith smith = Smith::correlated;
  double tolerance = 1e-10;
  int max_iterations = 1000;
  bool refine = false;  // least-squares refinement of both alphas against the tabulated NDF
};

struct FitResult {
  Extraction extraction;  // ndf, sigma, eigenvalue, iterations, residual
  FresnelCurve fresnel;
  double alpha_ggx = 0.0;
  double alpha_beckmann = 0.0;
  Rgb f0{0.0};   // F(0)
  Rgb f82{0.0};  // F(acos(1/7)), for the F82-tint Fresnel model
  Smith smith = Smith::correlated;  // the model the NDF is consistent with
  std::string problem;  // empty for a meaningful fit; otherwise why it is not one

  bool ok() const { return problem.empty(); }
  const TabulatedNdf& ndf() const { return extraction.ndf; }
};

// f(k, k) per theta_h bin: the mean over phi_d of the theta_d = 0 bins (one configuration, stored 180
// times), as luminance. Bins with no valid measurement are left out.
Backscatter backscatter_of(const MerlTable& table);

// Holds the quadrature of its resolution, so fitting many materials pays for it once. fit() is const
// and thread-safe.
class Fitter {
 public:
  explicit Fitter(const FitOptions& options);
  const FitOptions& options() const { return options_; }
  const Quadrature& quadrature() const { return quadrature_; }
  FitResult fit(const MerlTable& table) const;

 private:
  FitOptions options_;
  Quadrature quadrature_;
};

}  // namespace facetfit
