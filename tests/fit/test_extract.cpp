// Power-iteration extraction: convergence, the three Smith models, and the cost of mixing them.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "fit/fit.h"
#include "fit/roughness.h"
#include "model/analytic.h"

namespace facetfit {
namespace {

HalfDiffTable table_of(NdfType type, double alpha, Smith smith, const Fresnel& fresnel = Fresnel::schlick(Rgb(0.9, 0.6, 0.3))) {
  return HalfDiffTable::tabulate(MicrofacetBrdf(Ndf::isotropic(type, alpha), smith, fresnel));
}

FitResult fit_with(const HalfDiffTable& table, Smith smith, int max_iterations = 1000) {
  FitOptions options = FitOptions::paper();
  options.smith = smith;
  options.max_iterations = max_iterations;
  return Fitter(options).fit(table);
}

TEST(Extract, ConvergesToToleranceAndReportsIt) {
  const FitResult r = fit_with(table_of(NdfType::ggx, 0.4, Smith::correlated), Smith::correlated);
  ASSERT_TRUE(r.ok()) << r.problem;
  EXPECT_TRUE(r.extraction.converged);
  EXPECT_LE(r.extraction.residual, 1e-10);
  EXPECT_GT(r.extraction.iterations, 1);
  EXPECT_LT(r.extraction.iterations, 100);
}

TEST(Extract, NormalizedAndSigmaConsistent) {
  FitOptions options = FitOptions::paper();
  const Fitter fitter(options);
  const FitResult r = fitter.fit(table_of(NdfType::beckmann, 0.25, Smith::correlated));
  ASSERT_TRUE(r.ok());
  double area = 0.0;
  for (std::size_t j = 0; j < r.ndf().ndf.size(); ++j) area += fitter.quadrature().projected_area()[j] * r.ndf().ndf[j];
  EXPECT_NEAR(area, 1.0, 1e-12);
  // sigma(0) = 1 (the projected area seen from the normal) and sigma >= cos(theta) everywhere.
  EXPECT_NEAR(r.ndf().sigma.front(), 1.0, 1e-6);
  for (int j = 0; j < r.ndf().grid.size(); ++j) EXPECT_GE(r.ndf().sigma[std::size_t(j)], std::cos(r.ndf().grid.theta(j)) - 1e-9);
  // The eigenvalue is F0 of the luminance: Schlick F0 (0.9, 0.6, 0.3).
  EXPECT_NEAR(r.extraction.eigenvalue, luminance(Rgb(0.9, 0.6, 0.3)), 2e-3);
}

TEST(Extract, SigmaMatchesTheAnalyticProjectedArea) {
  const Ndf ndf = Ndf::isotropic(NdfType::ggx, 0.5);
  const FitResult r = fit_with(HalfDiffTable::tabulate(MicrofacetBrdf(ndf, Smith::correlated, Fresnel::one())), Smith::correlated);
  for (int j = 0; j < r.ndf().grid.size(); ++j) {
    const double theta = r.ndf().grid.theta(j);
    EXPECT_NEAR(r.ndf().sigma[std::size_t(j)], ndf.sigma(spherical_direction(theta, 0.0)), 2e-4) << "theta " << theta;
  }
}

TEST(Extract, MismatchedSmithBiasesRoughness) {
  // The reference implementation extracts with the masking assumption whatever made the data. On
  // height-correlated data that underestimates alpha of rough materials; the matching model does not.
  const HalfDiffTable table = table_of(NdfType::ggx, 0.7, Smith::correlated);
  const FitResult mismatched = fit_with(table, Smith::masking);
  const FitResult matched = fit_with(table, Smith::correlated);
  EXPECT_LT(mismatched.alpha_ggx, 0.67);
  EXPECT_NEAR(matched.alpha_ggx, 0.7, 0.7 * 0.005);
}

TEST(Extract, FourIterationsAreNotEnoughForRoughMaterials) {
  // dj_brdf stops after four iterations. Rough materials need more to converge.
  const HalfDiffTable table = table_of(NdfType::ggx, 1.0, Smith::correlated);
  const FitResult four = fit_with(table, Smith::correlated, 4);
  const FitResult converged = fit_with(table, Smith::correlated);
  EXPECT_FALSE(four.extraction.converged);
  EXPECT_GT(four.extraction.residual, 1e-4);
  EXPECT_GT(std::abs(four.alpha_ggx - 1.0), 5.0 * std::abs(converged.alpha_ggx - 1.0));
}

TEST(Extract, ResolutionsAgree) {
  const HalfDiffTable table = table_of(NdfType::ggx, 0.3, Smith::correlated);
  for (int resolution : {32, 64, 90, 128, 256}) {
    FitOptions options = FitOptions::paper();
    options.resolution = resolution;
    const FitResult r = Fitter(options).fit(table);
    ASSERT_TRUE(r.ok()) << resolution;
    EXPECT_NEAR(r.alpha_ggx, 0.3, 0.3 * 0.005) << "resolution " << resolution;
  }
}

TEST(Extract, RefinedAlphaOfTheOtherFamilyFitsDBest) {
  // A Beckmann material: the GGX moment estimate is biased, refine_alpha's GGX alpha fits D best.
  const Fitter fitter{FitOptions::paper()};
  const FitResult r = fitter.fit(table_of(NdfType::beckmann, 0.3, Smith::correlated));
  EXPECT_NEAR(r.alpha_beckmann, 0.3, 0.3 * 0.005);
  const double alpha = refine_alpha(fitter.quadrature(), r.ndf(), NdfType::ggx, r.alpha_ggx);
  const double at_refined = ndf_distance(fitter.quadrature(), r.ndf(), Ndf::isotropic(NdfType::ggx, alpha));
  for (double f : {0.9, 0.95, 1.05, 1.1})
    EXPECT_LT(at_refined, ndf_distance(fitter.quadrature(), r.ndf(), Ndf::isotropic(NdfType::ggx, alpha * f)));
}

TEST(Extract, BadResolutionIsAClearError) {
  FitOptions options = FitOptions::paper();
  options.resolution = 1;
  EXPECT_THROW(Fitter{options}, Error);
}

}  // namespace
}  // namespace facetfit
