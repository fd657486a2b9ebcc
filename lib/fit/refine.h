// Refinement of a fit on the whole measurement: body + tabulated microfacet lobe.
//
// The power iteration sees only back-scattering and a single lobe. Real materials also have a body
// (subsurface, diffuse reflection) and noise, so starting from the extraction, every parameter is
// refined against every bin the fit samples (fit/measurement.h), in that file's metric:
//
//   f(o, i) = body / pi + F(theta_d) D(theta_h) G2(o, i) / (4 cos theta_i cos theta_o)
//
// with the NDF nodes D, the RGB Fresnel curve F and the RGB body albedo as unknowns, bounded below by
// zero. G2 depends on every D node through sigma, densely, so it is held fixed within a pass (each bin
// then depends on a few D nodes, one or two Fresnel entries and the body: ~140 unknowns on an RGL file,
// ~320 on a UTIA file's nodes, solved by fit/small_problem.h's dense Levenberg-Marquardt, whose n x n
// normal equations grow with --resolution as the quadrature does), recomputed between passes. The
// result is not the joint optimum (docs/extraction.md): the caller keeps the start where it ends farther from the
// measurement. The NDF keeps its normalization through a stiff residual, the Fresnel curve is kept
// smooth by a small second-difference penalty.
#pragma once

#include "fit/fresnel_fit.h"
#include "fit/measurement.h"
#include "fit/quadrature.h"
#include "model/tabulated.h"
#include "model/tabulated_ndf.h"
#include "model/coat.h"
#include "model/smith.h"

namespace facetfit {

// What a body + tabulated-lobe fit holds.
struct LobeFit {
  TabulatedNdf ndf;
  FresnelCurve fresnel;
  Rgb body{0.0};  // albedo at normal incidence (model/body.h)
  Coat coat;      // held as it is by the refinement
  double body_exponent = 1.0;  // Minnaert's k (model/body.h)

  // What the tabulated model evaluates.
  MicrofacetTables tables(Smith smith) const { return {ndf, smith, fresnel, body, coat, body_exponent}; }
};

struct RefineOptions {
  // G2 recomputed from D between passes. Each pass is solved to convergence (6 to 15 steps on the RGL
  // files; the cap is a guard): one pass lets D drift away from the G2 it holds (acrylic_felt 0.0113
  // after one pass, 0.0104 after two: docs/extraction.md).
  int passes = 2;
  int max_iterations = 50;  // Levenberg-Marquardt steps per pass
  double function_tolerance = 1e-7;
  double fresnel_smoothness = 1e-3;
  // Weight of the NDF's second differences over the nodes, relative to the start's D at the node: keeps
  // the lobe from trading kinks near the peak against a coat or noise (a spline through kinks is also
  // what a float renderer evaluates least accurately).
  double ndf_smoothness = 0.01;
  // Where given, the lobe also matches the measurement's directional albedo (fit/measurement.h): a lobe whose
  // shape is shared by the three channels otherwise spends a colour that only the directions the bins weigh
  // least hold (chm_light_blue: a blue peak a degree wide over a grey haze, whose tabulated fit rendered grey).
  const AlbedoTarget* albedo = nullptr;
};

// sigma(theta_j) of the NDF nodes (the projected-area integral), and the NDF renormalized to unit
// projected area. Returns the area before renormalization.
double normalize_ndf(TabulatedNdf& ndf, const Quadrature& quadrature);

// The largest relative difference, over `bins`, between the refinement's hand-written derivatives and
// central differences at `at` (its ndf on `quadrature`'s grid): tests/fit/test_refine.cpp's check.
double refine_jacobian_error(const MeasuredBins& bins, const Quadrature& quadrature, Smith smith, const LobeFit& at);

// Refines `start` (its ndf on `quadrature`'s grid) on `bins`; its coat, if any, is held.
LobeFit refine_lobe(const MeasuredBins& bins, const Quadrature& quadrature, Smith smith, const LobeFit& start,
                    const RefineOptions& options);

}  // namespace facetfit
