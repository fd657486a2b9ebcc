// Which representation of a fit a renderer should use, and that representation's own parameters: what
// `fit`'s table, `info`, the JSON record, the LUT and Python all name, from this one function.
#pragma once

#include <optional>
#include <string>

#include "fit/fit.h"

namespace facetfit {

enum class Representation { tabulated, ggx, beckmann, closures };
const char* to_string(Representation r);
std::optional<Representation> parse_representation(const std::string& name);

// The default of `--tolerance`.
constexpr double kDefaultTolerance = 0.02;

// The distance a cheaper representation may add to the nearest one's whatever the tolerance: 0.2 L* units.
// The metric is CIE L*'s lightness / 116, and a lightness difference of 0.2 is at most 0.2 Delta E 2000 (its
// S_L is at least 1): the bar a recommendation is held to in the rendered report (within 0.2 of the nearest
// render). Judged on the fourteen RGL materials: 0.005 (0.6 L* units, the JND) let the closures stand in for a
// tabulated lobe 0.0038 nearer that rendered 0.26 Delta E better (docs/accuracy-notes.md).
constexpr double kAbsoluteTolerance = 0.2 / 116.0;

// The cheapest representation to shade whose distance from the measurement (fit/measurement.h judged_distance:
// the bins' and the albedo's, which ranks as renders do) is at most max((1 + tolerance) d, d + kAbsoluteTolerance),
// d the nearest one's: the GGX or Beckmann fit (one of a renderer's own closures; the nearer of the two), else the
// closures (one to three of them, what the production material emits), else the tabulated lobe (a table a
// renderer's closures cannot take; facetfit's renderer and the preview shader render it). Closures with no
// distance (0: not fitted, as with --refine none) are not a candidate.
Representation recommend(double error_tabulated, double error_ggx, double error_beckmann, double error_closures, double tolerance);
Representation recommend(const FitResult& fit, double tolerance);

// A representation's own parameters, as it renders: the parametric fit's for ggx and beckmann; for the
// tabulated one its Fresnel curve at 0 and 82 degrees, its body and coat, and no alpha (the NDF is a
// table); for the closures their body and coat, and their first lobe's Fresnel at 0 and 82 degrees (their
// lobes in full in the record's `closures`).
struct RepresentationParameters {
  Representation representation;
  std::optional<double> alpha;
  Rgb f0, f82, body;
  Coat coat;
  double error;  // distance from the measurement
};
RepresentationParameters parameters_of(const FitResult& fit, Representation r);
// The closures' (above), of closures `c` at distance `error`.
RepresentationParameters closures_parameters(const Closures& c, double error);

}  // namespace facetfit
