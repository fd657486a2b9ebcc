#include "fit/recommend.h"

#include <algorithm>

namespace facetfit {

const char* to_string(Representation r) {
  switch (r) {
    case Representation::tabulated: return "tabulated";
    case Representation::ggx: return "ggx";
    case Representation::beckmann: return "beckmann";
    case Representation::closures: return "closures";
  }
  return "?";
}

std::optional<Representation> parse_representation(const std::string& name) {
  for (Representation r : {Representation::tabulated, Representation::ggx, Representation::beckmann, Representation::closures})
    if (name == to_string(r)) return r;
  return std::nullopt;
}

Representation recommend(double error_tabulated, double error_ggx, double error_beckmann, double error_closures, double tolerance) {
  const bool closures_fitted = error_closures > 0.0;
  double nearest = error_tabulated;
  for (double e : {error_ggx, error_beckmann, closures_fitted ? error_closures : error_tabulated}) nearest = std::min(nearest, e);
  const double bar = std::max(nearest * (1.0 + tolerance), nearest + kAbsoluteTolerance);
  // A distance that is not a number (a fit that failed, or a NaN bar) never passes.
  const bool ggx = error_ggx <= bar, beckmann = error_beckmann <= bar;
  if (ggx && beckmann) return error_ggx <= error_beckmann ? Representation::ggx : Representation::beckmann;
  if (ggx) return Representation::ggx;
  if (beckmann) return Representation::beckmann;
  if (closures_fitted && error_closures <= bar) return Representation::closures;
  return Representation::tabulated;
}

Representation recommend(const FitResult& fit, double tolerance) {
  // An anisotropic source's closures are its anisotropic GGX fit, whose distance is measured on the source's
  // own pairs, not on the bins of the others: not comparable, so not a candidate.
  return recommend(fit.error, fit.ggx.error, fit.beckmann.error, fit.anisotropic ? 0.0 : fit.closures.error, tolerance);
}

RepresentationParameters closures_parameters(const Closures& c, double error) {
  const ClosureLobe& first = c.lobes.front();
  return {Representation::closures, std::nullopt, first.weight * first.fresnel_at(1.0), first.weight * first.fresnel_at(1.0 / 7.0),
          c.body, c.coat, error};
}

RepresentationParameters parameters_of(const FitResult& fit, Representation r) {
  if (r == Representation::tabulated) return {r, std::nullopt, fit.f0, fit.f82, fit.body(), fit.lobe.coat, fit.error};
  if (r == Representation::closures) return closures_parameters(fit.closures.closures, fit.closures.error);
  const ParametricFit& p = r == Representation::ggx ? fit.ggx : fit.beckmann;
  return {r, p.alpha, p.f0, p.f82, p.body, p.coat, p.error};
}

}  // namespace facetfit
