// The analytic ground truth itself: if these are wrong, every accuracy figure is.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/halfdiff.h"
#include "fit/quadrature.h"
#include "model/analytic.h"
#include "model/fresnel.h"
#include "model/ndf.h"

namespace facetfit {
namespace {

// Integral over the hemisphere of g(theta, phi) dw, by Gauss-Legendre in u = sqrt(2 theta / pi) and phi.
template <class G>
double hemisphere_integral(G g, int n_theta = 400, int n_phi = 256) {
  std::vector<double> x, w;
  gauss_legendre(n_theta, x, w);
  double sum = 0.0;
  for (int a = 0; a < n_theta; ++a) {
    const double u = x[a], theta = u * u * 0.5 * kPi;
    double ring = 0.0;
    for (int b = 0; b < n_phi; ++b) ring += g(theta, (b + 0.5) * 2.0 * kPi / n_phi);
    sum += w[a] * kPi * u * std::sin(theta) * ring * 2.0 * kPi / n_phi;
  }
  return sum;
}

class NdfTest : public testing::TestWithParam<std::tuple<NdfType, double, double>> {};

TEST_P(NdfTest, ProjectedAreaIsOne) {
  const auto [type, ax, ay] = GetParam();
  const Ndf ndf{type, ax, ay};
  const double area = hemisphere_integral([&](double t, double p) { return ndf.D(spherical_direction(t, p)) * std::cos(t); });
  EXPECT_NEAR(area, 1.0, 2e-4);
}

TEST_P(NdfTest, SigmaMatchesItsIntegral) {
  const auto [type, ax, ay] = GetParam();
  const Ndf ndf{type, ax, ay};
  for (double theta_k : {0.0, 0.4, 1.0, 1.4, 1.55, 0.5 * kPi, 1.7}) {
    const Vec3 k = spherical_direction(theta_k, 0.7);
    const double sigma = hemisphere_integral(
        [&](double t, double p) { return std::max(0.0, glm::dot(k, spherical_direction(t, p))) * ndf.D(spherical_direction(t, p)); });
    EXPECT_NEAR(ndf.sigma(k), sigma, 5e-4 * std::max(1.0, sigma)) << "theta_k " << theta_k;
  }
}

// D is the slope density over cos^4 (ndf.h), however it is computed (GGX's is multiplied out).
TEST_P(NdfTest, DIsTheSlopeDensityOverCosineToTheFourth) {
  const auto [type, ax, ay] = GetParam();
  const Ndf ndf{type, ax, ay};
  for (double theta : {0.0, 0.3, 1.0, 1.5, 1.5707})
    for (double phi : {0.0, 0.8, 2.5}) {
      const Vec3 h = spherical_direction(theta, phi);
      const double c4 = h.z * h.z * h.z * h.z;
      EXPECT_NEAR(ndf.D(h), ndf.slope_pdf(-h.x / h.z, -h.y / h.z) / c4, 1e-12 * ndf.D(h)) << theta << " " << phi;
    }
  EXPECT_EQ(ndf.D(Vec3(0.6, 0.0, -0.8)), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Shapes, NdfTest,
                         testing::Values(std::make_tuple(NdfType::ggx, 0.3, 0.3), std::make_tuple(NdfType::ggx, 0.8, 0.2),
                                         std::make_tuple(NdfType::beckmann, 0.3, 0.3),
                                         std::make_tuple(NdfType::beckmann, 0.15, 0.6),
                                         std::make_tuple(NdfType::ggx, 1.5, 1.5)));

TEST(Smith, BackScatteringForms) {
  // masking: G2(k,k) = G1(k); correlated: 1/(1+2 Lambda); separable: G1^2.
  const double lambda = 0.37, g1 = 1.0 / (1.0 + lambda);
  EXPECT_DOUBLE_EQ(smith_g2(Smith::masking, lambda, lambda), g1);
  EXPECT_DOUBLE_EQ(smith_g2(Smith::correlated, lambda, lambda), 1.0 / (1.0 + 2.0 * lambda));
  EXPECT_DOUBLE_EQ(smith_g2(Smith::separable, lambda, lambda), g1 * g1);
  for (Smith s : {Smith::masking, Smith::correlated, Smith::separable}) {
    EXPECT_NEAR(smith_g2_from_g1(s, 1.0 / 1.2, 1.0 / 1.9), smith_g2(s, 0.2, 0.9), 1e-15);
    EXPECT_EQ(smith_g2_from_g1(s, 0.0, 0.5), 0.0);
    EXPECT_EQ(parse_smith(to_string(s)), s);
  }
}

TEST(Fresnel, KnownValues) {
  EXPECT_NEAR(fresnel_dielectric(1.5, 1.0), 0.04, 1e-12);
  EXPECT_DOUBLE_EQ(fresnel_dielectric(1.5, 0.0), 1.0);
  // Conductor at normal incidence: ((n-1)^2 + k^2) / ((n+1)^2 + k^2).
  const Rgb f = fresnel_conductor(Rgb(0.2), Rgb(3.9), 1.0);
  EXPECT_NEAR(f.r, (0.64 + 3.9 * 3.9) / (1.44 + 3.9 * 3.9), 1e-12);
  EXPECT_NEAR(fresnel_schlick(Rgb(0.3), 0.0).g, 1.0, 1e-12);
  // F82-tint passes through f0 at normal incidence and f82 at acos(1/7).
  const Rgb f0(0.9, 0.6, 0.3), f82(0.8, 0.7, 0.5);
  EXPECT_NEAR(fresnel_f82_tint(f0, f82, 1.0).b, 0.3, 1e-12);
  EXPECT_NEAR(fresnel_f82_tint(f0, f82, 1.0 / 7.0).g, 0.7, 1e-12);
}

TEST(CubeRoot, AgreesWithTheLibraryOverEveryExponent) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> mantissa(1.0, 2.0);
  double worst = 0.0;
  for (int e = -1020; e <= 1020; e += 3)
    for (int n = 0; n < 64; ++n) {
      const double x = std::ldexp(mantissa(rng), e);
      worst = std::max(worst, std::abs(cube_root(x) - std::cbrt(x)) / std::cbrt(x));
    }
  for (const double x : {1.0, 8.0, 27.0, 0.125, 6.0 / 29.0 * 6.0 / 29.0 * 6.0 / 29.0, 1e-300, 1e300})
    worst = std::max(worst, std::abs(cube_root(x) - std::cbrt(x)) / std::cbrt(x));
  EXPECT_LT(worst, 1e-15);
  EXPECT_EQ(cube_root(0.0), 0.0);
  EXPECT_DOUBLE_EQ(cube_root(-8.0), -2.0);
  EXPECT_EQ(cube_root(HUGE_VAL), HUGE_VAL);
  EXPECT_TRUE(std::isnan(cube_root(std::nan(""))));
}

TEST(HalfDiff, RoundTrip) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n = 0; n < 1000; ++n) {
    const double th = u(rng) * 0.5 * kPi, td = u(rng) * 0.5 * kPi, pd = u(rng) * 2.0 * kPi - kPi;
    const auto [o, i] = from_half_diff(th, td, pd);
    const HalfDiff hd = to_half_diff(o, i);
    EXPECT_NEAR(hd.theta_h, th, 1e-7);
    EXPECT_NEAR(hd.theta_d, td, 1e-7);
    if (td > 1e-3 && th > 1e-3) {
      EXPECT_NEAR(std::remainder(hd.phi_d - pd, 2.0 * kPi), 0.0, 1e-6);
    }
    EXPECT_NEAR(glm::length(i), 1.0, 1e-12);
    EXPECT_NEAR(glm::length(o), 1.0, 1e-12);
  }
}

TEST(MicrofacetBrdf, ReciprocalAndZeroBelowHorizon) {
  const MicrofacetBrdf brdf(Ndf::isotropic(NdfType::ggx, 0.3), Smith::correlated, Fresnel::dielectric(1.5));
  const Vec3 a = spherical_direction(0.3, 0.1), b = spherical_direction(1.1, 2.0);
  EXPECT_NEAR(brdf.eval(b, a)->r, brdf.eval(a, b)->r, 1e-14);
  EXPECT_EQ(brdf.eval(spherical_direction(1.7, 0.0), a)->g, 0.0);
}

}  // namespace
}  // namespace facetfit
