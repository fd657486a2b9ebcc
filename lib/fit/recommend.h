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

// The cheapest representation to shade whose distance from the measurement (fit/measurement.h judged_distance:
// the bins' and the albedo's, which ranks as renders do) is at most max((1 + tolerance) d, d + 0.005), d the
// nearest one's: the GGX or Beckmann fit (one of a renderer's own closures; the nearer of the two), else the
// closures (one to three of them, what the production material emits), else the tabulated lobe (a table a
// renderer's closures cannot take; facetfit's renderer and the preview shader render it). The metric is CIE
// L*'s lightness / 116, so 0.005 is about 0.6 L* units, under a just-noticeable difference. Closures with no
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
