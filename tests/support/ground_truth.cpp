#include "support/ground_truth.h"

#include <cmath>

#include "fit/roughness.h"
#include "model/analytic.h"

namespace facetfit {

std::vector<GroundTruthCase> standard_ground_truth_cases() {
  const Fresnel gold = Fresnel::conductor({0.143, 0.374, 1.442}, {3.983, 2.385, 1.603});
  std::vector<GroundTruthCase> cases;
  for (NdfType type : {NdfType::ggx, NdfType::beckmann})
    for (Smith smith : {Smith::masking, Smith::correlated, Smith::separable})
      for (double alpha : {0.02, 0.05, 0.1, 0.2, 0.4, 0.7, 1.0}) cases.push_back({type, alpha, smith, gold});
  return cases;
}

GroundTruthError measure_ground_truth(const GroundTruthCase& c, const Fitter& fitter, const std::string& merl_path) {
  const Ndf ndf = Ndf::isotropic(c.type, c.alpha);
  MerlTable table = MerlTable::tabulate(MicrofacetBrdf(ndf, c.smith, c.fresnel));
  if (!merl_path.empty()) {
    table.write(merl_path);
    table = MerlTable::read(merl_path);
  }
  const FitResult fit = fitter.fit(table);
  GroundTruthError e;
  e.problem = fit.problem;
  e.iterations = fit.extraction.iterations;
  e.residual = fit.extraction.residual;
  if (!fit.ok()) return e;
  e.alpha = c.type == NdfType::ggx ? fit.alpha_ggx : fit.alpha_beckmann;
  e.alpha_relative = e.alpha / c.alpha - 1.0;
  e.ndf_l1 = ndf_distance(
      fitter.quadrature(), [&](double theta) { return ndf.D(spherical_direction(theta, 0.0)); },
      [&](double theta) { return fit.ndf().D(theta); });
  for (int j = 0; j < FresnelCurve::kSize; ++j) {
    const double theta_d = FresnelCurve::theta_d(j);
    if (theta_d > 80.0 * kPi / 180.0 + 1e-9) break;
    const Rgb d = glm::abs(fit.fresnel().value[std::size_t(j)] - c.fresnel.eval(std::cos(theta_d)));
    e.fresnel_abs = std::max({e.fresnel_abs, d.r, d.g, d.b});
  }
  return e;
}

}  // namespace facetfit
