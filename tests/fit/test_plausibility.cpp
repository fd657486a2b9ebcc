// Implausible measurements and fits are reported, one line each (fit/plausibility.h).
#include <gtest/gtest.h>

#include "fit/fit.h"
#include "fit/plausibility.h"
#include "model/analytic.h"

namespace facetfit {
namespace {

bool mentions(const std::vector<std::string>& warnings, const std::string& what) {
  for (const std::string& w : warnings)
    if (w.find(what) != std::string::npos) return true;
  return false;
}

std::shared_ptr<const Brdf> ggx(double alpha, const Fresnel& fresnel) {
  return std::make_shared<MicrofacetBrdf>(Ndf::isotropic(NdfType::ggx, alpha), Smith::correlated, fresnel);
}

TEST(Plausibility, DirectionalAlbedoOfLambertIsItsAlbedo) {
  const LambertBrdf lambert(Rgb(0.2, 0.5, 0.9));
  for (const double theta : {0.0, 0.7, 1.4}) {
    const Rgb rho = directional_albedo(lambert, spherical_direction(theta, 0.3));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(rho[c], lambert.eval({0, 0, 1}, {0, 0, 1})->operator[](c) * kPi, 1e-9);
  }
}

TEST(Plausibility, APlausibleMaterialHasNoWarning) {
  const SumBrdf truth({std::make_shared<LambertBrdf>(Rgb(0.5, 0.3, 0.1)), ggx(0.2, Fresnel::schlick(Rgb(0.04)))});
  const FitResult r = Fitter(FitOptions{}).fit(HalfDiffTable::tabulate(truth));
  ASSERT_TRUE(r.ok()) << r.problem;
  EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
}

TEST(Plausibility, AlbedoAboveOneAndFresnelAboveOneAreReported) {
  // A body of albedo 1.3 in red: more light out than in, at every angle.
  const SumBrdf truth({std::make_shared<LambertBrdf>(Rgb(1.3, 0.3, 0.1)), ggx(0.2, Fresnel::schlick(Rgb(0.04)))});
  const FitResult r = Fitter(FitOptions{}).fit(HalfDiffTable::tabulate(truth));
  ASSERT_TRUE(r.ok()) << r.problem;
  EXPECT_TRUE(mentions(r.warnings, "directional albedo of the measurement above 1")) << ::testing::PrintToString(r.warnings);
  EXPECT_TRUE(mentions(r.warnings, "directional albedo of the tabulated fit above 1")) << ::testing::PrintToString(r.warnings);
  // A lobe whose Fresnel is 1.5 (a mis-scaled measurement): the paper's fit reads it as F > 1.
  const FitResult bright = Fitter(FitOptions::paper()).fit(HalfDiffTable::tabulate(*ggx(0.3, Fresnel::schlick(Rgb(1.5)))));
  ASSERT_TRUE(bright.ok()) << bright.problem;
  EXPECT_TRUE(mentions(bright.warnings, "Fresnel factor above 1")) << ::testing::PrintToString(bright.warnings);
}

TEST(Plausibility, NegativeMeasurementsAreCountedPerChannel) {
  HalfDiffTable table = HalfDiffTable::tabulate(*ggx(0.3, Fresnel::schlick(Rgb(0.9))));
  for (int i = 40; i < 60; ++i) table.set(i, 10, 5, Rgb(0.5, 0.5, -0.01));
  const FitResult r = Fitter(FitOptions::paper()).fit(table);
  ASSERT_TRUE(r.ok()) << r.problem;
  EXPECT_TRUE(mentions(r.warnings, "negative in the blue channel")) << ::testing::PrintToString(r.warnings);
  EXPECT_FALSE(mentions(r.warnings, "negative in the red channel"));
}

}  // namespace
}  // namespace facetfit
