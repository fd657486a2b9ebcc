#include "fit/recommend.h"

#include <algorithm>

namespace facetfit {

const char* to_string(Representation r) {
  switch (r) {
    case Representation::tabulated: return "tabulated";
    case Representation::ggx: return "ggx";
    case Representation::beckmann: return "beckmann";
  }
  return "?";
}

std::optional<Representation> parse_representation(const std::string& name) {
  for (Representation r : {Representation::tabulated, Representation::ggx, Representation::beckmann})
    if (name == to_string(r)) return r;
  return std::nullopt;
}

Representation recommend(double error_tabulated, double error_ggx, double error_beckmann, double tolerance) {
  const double bar = std::max(error_tabulated * (1.0 + tolerance), error_tabulated + 0.005);
  // A distance that is not a number (a fit that failed, or a NaN bar) never passes.
  const bool ggx = error_ggx <= bar, beckmann = error_beckmann <= bar;
  if (ggx && beckmann) return error_ggx <= error_beckmann ? Representation::ggx : Representation::beckmann;
  if (ggx) return Representation::ggx;
  return beckmann ? Representation::beckmann : Representation::tabulated;
}

Representation recommend(const FitResult& fit, double tolerance) {
  return recommend(fit.error, fit.ggx.error, fit.beckmann.error, tolerance);
}

RepresentationParameters parameters_of(const FitResult& fit, Representation r) {
  if (r == Representation::tabulated) return {r, std::nullopt, fit.f0, fit.f82, fit.body(), fit.lobe.coat, fit.error};
  const ParametricFit& p = r == Representation::ggx ? fit.ggx : fit.beckmann;
  return {r, p.alpha, p.f0, p.f82, p.body, p.coat, p.error};
}

}  // namespace facetfit
