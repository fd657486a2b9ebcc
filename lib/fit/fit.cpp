#include "fit/fit.h"

#include <cmath>

#include "core/error.h"
#include "fit/roughness.h"
#include "model/fresnel.h"

namespace facetfit {

Backscatter backscatter_of(const MerlTable& table) {
  Backscatter back;
  for (int i = 0; i < MerlTable::kThetaH; ++i) {
    Rgb mean(0.0);
    bool complete = true;
    for (int c = 0; c < 3 && complete; ++c) {
      const float* row = table.channel(c) + MerlTable::index(i, 0, 0);
      double sum = 0.0;
      int n = 0;
      for (int k = 0; k < MerlTable::kPhiD; ++k) {
        if (row[k] < 0.0f) continue;
        sum += row[k];
        ++n;
      }
      complete = n > 0;
      mean[c] = n > 0 ? sum / n : 0.0;
    }
    if (!complete) continue;
    back.theta.push_back(MerlTable::theta_h(i));
    back.value.push_back(luminance(mean));
  }
  return back;
}

namespace {

Quadrature checked_quadrature(const FitOptions& options) {
  if (options.resolution < 4 || options.resolution > 4096)
    fail("--resolution " + std::to_string(options.resolution), "must be between 4 and 4096");
  return Quadrature(options.resolution);
}

}  // namespace

Fitter::Fitter(const FitOptions& options) : options_(options), quadrature_(checked_quadrature(options)) {}

FitResult Fitter::fit(const MerlTable& table) const {
  FitResult result;
  result.smith = options_.smith;
  result.extraction = extract_ndf(backscatter_of(table), quadrature_,
                                  {options_.smith, options_.tolerance, options_.max_iterations});
  if (!result.extraction.problem.empty()) {
    result.problem = result.extraction.problem;
    return result;
  }
  result.fresnel = fit_fresnel(table, result.ndf(), options_.smith, &result.problem);
  if (!result.ok()) return result;

  result.alpha_ggx = alpha_ggx_from_moments(result.ndf(), quadrature_);
  result.alpha_beckmann = alpha_beckmann_from_moments(result.ndf(), quadrature_);
  if (options_.refine) {
    result.alpha_ggx = refine_alpha(quadrature_, result.ndf(), NdfType::ggx, result.alpha_ggx);
    result.alpha_beckmann = refine_alpha(quadrature_, result.ndf(), NdfType::beckmann, result.alpha_beckmann);
  }
  result.f0 = result.fresnel.value[0];
  result.f82 = result.fresnel.eval(f82_theta());

  const auto finite = [](const Rgb& c) { return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b); };
  if (!std::isfinite(result.alpha_ggx) || !std::isfinite(result.alpha_beckmann) || !finite(result.f0) || !finite(result.f82))
    result.problem = "the fit produced non-finite parameters";
  return result;
}

}  // namespace facetfit
