// Which representation of a fit a renderer should use, and that representation's own parameters: what
// `fit`'s table, `info`, the JSON record, the LUT and Python all name, from this one function.
#pragma once

#include <optional>
#include <string>

#include "fit/fit.h"

namespace facetfit {

enum class Representation { tabulated, ggx, beckmann };
const char* to_string(Representation r);
std::optional<Representation> parse_representation(const std::string& name);

// The default of `--tolerance`.
constexpr double kDefaultTolerance = 0.02;

// The GGX or Beckmann fit, whichever is nearer the measurement, when its distance from the measurement
// (fit/measurement.h) is at most max((1 + tolerance) d, d + 0.005), d the tabulated representation's:
// it renders with a renderer's own closure and is then nearly as good. The tabulated one otherwise. The
// metric is CIE L*'s lightness / 116, so 0.005 is about 0.6 L* units, under a just-noticeable difference.
Representation recommend(double error_tabulated, double error_ggx, double error_beckmann, double tolerance);
Representation recommend(const FitResult& fit, double tolerance);

// A representation's own parameters, as it renders: the parametric fit's for ggx and beckmann; for the
// tabulated one its Fresnel curve at 0 and 82 degrees, its body and coat, and no alpha (the NDF is a
// table).
struct RepresentationParameters {
  Representation representation;
  std::optional<double> alpha;
  Rgb f0, f82, body;
  Coat coat;
  double error;  // distance from the measurement
};
RepresentationParameters parameters_of(const FitResult& fit, Representation r);

}  // namespace facetfit
