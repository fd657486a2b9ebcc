// The closure representation fitted on the whole measurement (model/closures.h): a Lambertian body, one
// to three GGX lobes, each with its own alpha, weight and Fresnel (F82-tint or generalized Schlick), and
// the coat, in the metric of fit/measurement.h, with the closures' own formulas (height-correlated Smith
// G2, as Cycles).
//
// Besides the bins, the closures match the measurement's directional albedo (fit/measurement.h AlbedoTarget), beyond a
// tolerance: the bins weigh grazing pairs down (fit/measurement.h) and an RGL file has none past 78.5
// degrees, so a sum of closures fitted to them alone returned far more light at grazing views than the
// measurement (0.95 of it at 85 degrees on ilm_l3_37_metallic, where the tabulated lobe returns 0.48): a
// sphere's rim, in every rendering under an environment.
//
// The start is the one-lobe GGX fit (fit/parametric_fit.h) with its coat, its lobe at weight 1: GGX
// because every renderer and MaterialX's generalized_schlick_bsdf have it (Cycles' Beckmann masking is
// a rational approximation, and MaterialX has no Beckmann). Lobes are then added one at a time: from the
// current fit, a sharper and a broader lobe are tried, every parameter solved again (on a third of the
// bins' rows, a few steps each), and the nearer taken if it brings the fit `lobe_gain` of its distance
// nearer; otherwise no more are added; the lobes chosen are then solved on every row. So no lobe stays
// that does not pay for itself, and a material that is one lobe keeps one.
#pragma once

#include <functional>

#include "fit/measurement.h"
#include "fit/parametric_fit.h"
#include "model/closures.h"
#include "model/proposal.h"

namespace facetfit {

struct ClosureFitOptions {
  int max_lobes = Closures::kMaxLobes;
  double lobe_gain = 0.03;  // the relative distance a lobe must buy to be kept
  double min_gain = 2e-4;   // and the least (0.02 units of L*)
  int max_iterations = 15;     // Levenberg-Marquardt steps per solve while lobes are chosen
  int polish_iterations = 25;  // and of the solve of the lobes chosen (the six RGL materials' distances within 1% of 200 steps')
  // f82_tint: the start's lobe keeps its F82-tint Fresnel; schlick: it starts as the nearest generalized
  // Schlick (model/closures.h, without_f82), so that every lobe is one (what MaterialX's OSL renders exactly).
  ClosureLobe::Fresnel fresnel = ClosureLobe::Fresnel::f82_tint;
  // What chooses between the fits of the two starts (the lobes added one at a time; three at once): the
  // smaller of its values, else the smaller objective.
  std::function<double(const Closures&)> judge;
};

struct ClosureFit {
  Closures closures;
  double error = 0.0;  // measurement_error of the closures on the error bins
};

// Solves on `bins` and, where given, `albedo`; measures on `error_bins`. `start` is a GGX fit.
ClosureFit fit_closures(const MeasuredBins& bins, const AlbedoTarget* albedo, const MeasuredBins& error_bins,
                        const ParametricFit& start, const ClosureFitOptions& options = {});
// From closures already fitted (lobes are added to them while there is room and they pay).
ClosureFit fit_closures(const MeasuredBins& bins, const AlbedoTarget* albedo, const MeasuredBins& error_bins,
                        const Closures& start, const ClosureFitOptions& options = {});

// A one-lobe fit as closures: its lobe at weight 1, its body and coat.
Closures closures_of(const ParametricFit& fit);

// The closures of an anisotropic input: its anisotropic GGX fit (fit/parametric_fit.h) as one lobe along
// its axes, with its body.
Closures closures_of(const AnisotropicParametricFit& fit);

// The closures' directional albedo at cos theta_o as the fit's table sums it at its nodes (isotropic GGX
// lobes: visible normals at fixed points, fit/visible_moments.h), for tests against albedo_target of ClosureBrdf.
Rgb closure_albedo(const Closures& closures, double cos_o);

// The closures' distance from the measurement (measurement_error of ClosureBrdf).
double closure_error(const MeasuredBins& bins, const Closures& closures);

// The largest relative difference, over `bins` and where given the albedo's residuals, between the fit's
// hand-written derivatives and central differences at `at` (isotropic lobes): tests/fit/test_closures.cpp's check.
double closure_jacobian_error(const MeasuredBins& bins, const Closures& at, const AlbedoTarget* albedo = nullptr);

}  // namespace facetfit
