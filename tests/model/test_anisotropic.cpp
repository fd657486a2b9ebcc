// The anisotropic tabulated lobe (model/tabulated_anisotropic.h): its evaluation against the analytic
// model its tables come from, and its sampler against its density (chi-square in direction space at
// several view azimuths, one Bonferroni-corrected threshold for all of them).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "chi2.h"
#include "core/error.h"
#include "fit/extract_2d.h"
#include "fit/quadrature_2d.h"
#include "model/analytic.h"
#include "model/fresnel.h"
#include "model/tabulated_anisotropic.h"
#include "support/ground_truth.h"

namespace facetfit {
namespace {

// D and sigma of an analytic NDF with its axes turned by `angle`, at the grid's nodes.
AnisotropicTables analytic_tables(const Ndf& ndf, double angle, Smith smith, int resolution, int phi_count) {
  AnisotropicTables t;
  t.grid.resolution = resolution;
  t.phi_count = phi_count;
  t.smith = smith;
  for (int j = 0; j < FresnelCurve::kSize; ++j) t.fresnel.value[std::size_t(j)] = Rgb(1.0);
  for (int j = 0; j < t.grid.size(); ++j)
    for (int m = 0; m < phi_count; ++m) {
      const double theta = std::min(t.grid.theta(j), 0.5 * kPi - 1e-6);  // sigma's limit at the horizon
      const Vec3 w = spherical_direction(theta, 2.0 * kPi * m / phi_count - angle);
      t.ndf.push_back(ndf.D(w));
      t.sigma.push_back(ndf.sigma(w));
    }
  return t;
}

// Relative errors of the tabulated lobe against the analytic one over random pairs up to 80 degrees
// where f is not negligible; median and 95th percentile.
std::pair<double, double> eval_errors(const TabulatedAnisotropic& lobe, const Brdf& truth) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> e;
  const double c_min = std::cos(80.0 * kPi / 180.0);
  for (int n = 0; n < 4000; ++n) {
    const Vec3 o = spherical_direction(std::acos(1.0 - (1.0 - c_min) * u(rng)), 2.0 * kPi * u(rng));
    const Vec3 i = spherical_direction(std::acos(1.0 - (1.0 - c_min) * u(rng)), 2.0 * kPi * u(rng));
    const double f = (*truth.eval(o, i)).r;
    if (f < 0.05) continue;
    e.push_back(std::abs((*lobe.eval(o, i)).r / f - 1.0));
  }
  std::sort(e.begin(), e.end());
  return {e[e.size() / 2], e[e.size() * 95 / 100]};
}

TEST(TabulatedAnisotropic, EvaluatesAsTheAnalyticModelOfItsTables) {
  const Ndf ndf{NdfType::ggx, 0.4, 0.15};
  const double angle = 30.0 * kPi / 180.0;
  const TabulatedAnisotropic lobe(analytic_tables(ndf, angle, Smith::correlated, 90, 64));
  const MicrofacetBrdf model(ndf, Smith::correlated, Fresnel::one());
  const RotatedBrdf truth(model, angle);
  const auto [median, p95] = eval_errors(lobe, truth);
  std::printf("[ tabulated 2D ] analytic tables: median relative error %.2e, 95th percentile %.2e\n", median, p95);
  EXPECT_LT(median, 1e-3);
  EXPECT_LT(p95, 5e-3);
  // G1 from the tabulated projected area, at a direction between nodes (the NDF's frame is turned by angle).
  const Vec3 w = spherical_direction(1.2, 0.7), in_ndf_frame = spherical_direction(1.2, 0.7 - angle);
  EXPECT_NEAR(lobe.g1(w), ndf.g1(in_ndf_frame), 2e-3);
}

// The 2D extraction of the same material's back-scattering, as a lobe: what a fit would render.
TEST(TabulatedAnisotropic, TheExtractionsLobeEvaluatesAsTheMaterial) {
  const Ndf ndf{NdfType::ggx, 0.4, 0.15};
  const double angle = 30.0 * kPi / 180.0;
  const MicrofacetBrdf model(ndf, Smith::correlated, Fresnel::one());
  const RotatedBrdf truth(model, angle);
  const Quadrature2D quad(90, 64);
  const Extraction2D x = extract_ndf_2d(backscatter_2d(truth, quad), quad, {Smith::correlated, 1e-10, 1000});
  ASSERT_TRUE(x.problem.empty()) << x.problem;
  AnisotropicTables t;
  t.grid = quad.grid();
  t.phi_count = quad.phi_count();
  t.ndf = x.ndf;
  t.sigma = x.sigma;
  t.smith = Smith::correlated;
  for (int j = 0; j < FresnelCurve::kSize; ++j) t.fresnel.value[std::size_t(j)] = Rgb(1.0);
  const auto [median, p95] = eval_errors(TabulatedAnisotropic(t), truth);
  std::printf("[ tabulated 2D ] extracted tables: median relative error %.2e, 95th percentile %.2e\n", median, p95);
  EXPECT_LT(median, 2e-3);
  EXPECT_LT(p95, 1e-2);
}

// Chi-square of the lobe's draws against its pdf at each view (theta, phi in degrees), one Bonferroni-
// corrected threshold for all of them; each draw's weight is f cos / pdf.
void expect_samples_own_density(const TabulatedAnisotropic& lobe, const std::vector<std::pair<double, double>>& views, unsigned seed) {
  const double threshold = 0.01 / double(views.size());  // Bonferroni: 1% for the family
  for (const auto& [theta, phi] : views) {
    SCOPED_TRACE(theta);
    SCOPED_TRACE(phi);
    const Vec3 o = spherical_direction(theta * kPi / 180.0, phi * kPi / 180.0);
    const test::ChiSquareResult r = test::chi_square_in_directions(
        [&](double u1, double u2) -> std::optional<Vec3> {
          const auto s = lobe.sample(o, u1, u2);
          if (!s) return std::nullopt;
          EXPECT_NEAR(s->weight.r, (*lobe.eval(o, s->i)).r * s->i.z / lobe.pdf(o, s->i), 1e-9 * std::max(1.0, s->weight.r));
          return s->i;
        },
        [&](const Vec3& i) { return lobe.pdf(o, i); }, 200000, seed);
    EXPECT_GT(r.p_value, threshold) << "chi2 " << r.statistic << " dof " << r.dof;
  }
}

TEST(TabulatedAnisotropic, SamplesItsOwnDensity) {
  const Ndf ndf{NdfType::ggx, 0.4, 0.15};
  const TabulatedAnisotropic lobe(analytic_tables(ndf, 30.0 * kPi / 180.0, Smith::correlated, 90, 64));
  expect_samples_own_density(lobe, {{30, 0}, {30, 50}, {30, 135}, {70, 260}, {70, 20}, {55, 95}}, 11);
  // Negative control: the draws of this lobe against the density of the lobe turned 20 degrees fail.
  const TabulatedAnisotropic turned(analytic_tables(ndf, 50.0 * kPi / 180.0, Smith::correlated, 90, 64));
  const Vec3 o = spherical_direction(40.0 * kPi / 180.0, 0.3);
  const test::ChiSquareResult wrong = test::chi_square_in_directions(
      [&](double u1, double u2) -> std::optional<Vec3> {
        const auto s = lobe.sample(o, u1, u2);
        return s ? std::optional<Vec3>(s->i) : std::nullopt;
      },
      [&](const Vec3& i) { return turned.pdf(o, i); }, 200000, 12);
  EXPECT_LT(wrong.p_value, 1e-6);
}

// The artist's stretch on the anisotropic lobe (model/stretch.h): GGX 0.4 x 0.15 with its x axis at 30
// degrees (the tables' axis), its slopes scaled by 0.5 along that axis and 2 across it, is the analytic GGX
// 0.2 x 0.3 there, in eval, in sampling (chi-square against its own pdf, which the first part ties to the
// analytic model) and in albedo; a rotation turns it, alone or with the scales.
TEST(TabulatedAnisotropic, StretchedIsTheStretchedAnalyticModel) {
  const double angle = 30.0 * kPi / 180.0, turn = 20.0 * kPi / 180.0;
  AnisotropicTables tables = analytic_tables(Ndf{NdfType::ggx, 0.4, 0.15}, angle, Smith::correlated, 90, 64);
  tables.axis = angle;
  const TabulatedAnisotropic measured(tables);
  const TabulatedAnisotropic lobe = measured.stretched(Stretch(0.5, 2.0));
  const MicrofacetBrdf model(Ndf{NdfType::ggx, 0.2, 0.3}, Smith::correlated, Fresnel::one());
  const RotatedBrdf truth(model, angle);
  const auto [median, p95] = eval_errors(lobe, truth);
  std::printf("[ tabulated 2D, stretched ] median relative error %.2e, 95th percentile %.2e\n", median, p95);
  EXPECT_LT(median, 1e-3);
  EXPECT_LT(p95, 5e-3);
  // The unstretched lobe is far from it: the comparison sees the stretch.
  EXPECT_GT(eval_errors(measured, truth).first, 0.1);
  // Turned by 20 degrees: the lobe's axes at 50, with and without the scales; the unturned lobe is far.
  const MicrofacetBrdf unscaled_model(Ndf{NdfType::ggx, 0.4, 0.15}, Smith::correlated, Fresnel::one());
  const RotatedBrdf turned(unscaled_model, angle + turn), turned_scaled(model, angle + turn);
  EXPECT_LT(eval_errors(measured.stretched(Stretch(1.0, 1.0, turn)), turned).first, 1e-3);
  EXPECT_LT(eval_errors(measured.stretched(Stretch(0.5, 2.0, turn)), turned_scaled).first, 1e-3);
  EXPECT_GT(eval_errors(measured, turned).first, 0.1);
  expect_samples_own_density(measured.stretched(Stretch(1.0, 1.0, turn)), {{30, 0}, {55, 95}}, 14);

  const std::vector<std::pair<double, double>> views = {{30, 0}, {30, 135}, {70, 260}, {55, 95}};
  expect_samples_own_density(lobe, views, 13);
  for (const auto& [theta, phi] : views) {
    const Vec3 o = spherical_direction(theta * kPi / 180.0, phi * kPi / 180.0);
    // Albedo by the lobe's own sampling against the analytic model's, estimated with as many directions
    // uniform over the hemisphere.
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    double sampled = 0.0, uniform = 0.0;
    constexpr int kN = 200000;
    for (int n = 0; n < kN; ++n) {
      if (const auto s = lobe.sample(o, u(rng), u(rng))) sampled += s->weight.r;
      const Vec3 i = spherical_direction(std::acos(u(rng)), 2.0 * kPi * u(rng));
      uniform += (*truth.eval(o, i)).r * i.z * 2.0 * kPi;
    }
    EXPECT_NEAR(sampled / kN, uniform / kN, 0.01 * uniform / kN);
  }
}

TEST(TabulatedAnisotropic, RefusesTablesOfTheWrongSize) {
  AnisotropicTables t = analytic_tables(Ndf{NdfType::ggx, 0.3, 0.3}, 0.0, Smith::correlated, 16, 8);
  t.sigma.pop_back();
  EXPECT_THROW(TabulatedAnisotropic{t}, Error);
}

}  // namespace
}  // namespace facetfit
