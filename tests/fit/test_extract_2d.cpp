// Anisotropic extraction (fit/extract_2d.h): isotropic inputs give the isotropic answer, anisotropic and
// rotated GGX and Beckmann come back with their principal alphas and angle, for every Smith model.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "fit/extract_2d.h"
#include "fit/roughness.h"
#include "model/ndf.h"
#include "model/smith.h"
#include "support/ground_truth.h"

namespace facetfit {
namespace {

// f(k, k) of a microfacet BRDF with F = 1 whose NDF's x axis lies at azimuth `angle`, at MERL's theta_h
// bins: F D(k) G2(k, k) / (4 cos^2 theta_k).
Backscatter slice(const Ndf& ndf, double angle, Smith smith, double phi) {
  Backscatter b;
  for (int i = 0; i < 90; ++i) {
    const double t = double(i) / 90.0, theta = t * t * 0.5 * kPi;
    const Vec3 k = spherical_direction(theta, phi - angle);  // into the NDF's own frame
    const double lambda = ndf.lambda(k);
    b.theta.push_back(theta);
    b.value.push_back(ndf.D(k) * smith_g2(smith, lambda, lambda) / (4.0 * k.z * k.z));
  }
  return b;
}

Backscatter2D backscatter(const Ndf& ndf, double angle, Smith smith, const Quadrature2D& quad) {
  Backscatter2D b;
  for (int m = 0; m < quad.phi_count(); ++m) b.slices.push_back(slice(ndf, angle, smith, quad.phi(m)));
  return b;
}

TEST(Extract2D, IsotropicInputGivesTheIsotropicResult) {
  const Quadrature2D quad(90, 32);
  for (Smith smith : {Smith::masking, Smith::correlated, Smith::separable}) {
    const Ndf ndf = Ndf::isotropic(NdfType::ggx, 0.3);
    const Extraction2D e = extract_ndf_2d(backscatter(ndf, 0.0, smith, quad), quad, {smith, 1e-10, 1000});
    ASSERT_TRUE(e.problem.empty()) << e.problem;
    EXPECT_TRUE(e.converged);
    const Extraction iso = extract_ndf(slice(ndf, 0.0, smith, 0.0), quad.base(), {smith, 1e-10, 1000});
    ASSERT_TRUE(iso.problem.empty());
    // Every azimuth holds the isotropic D, to the projected area's weight.
    double diff = 0.0;
    for (int j = 0; j < quad.size(); ++j)
      for (int m = 0; m < quad.phi_count(); ++m)
        diff += quad.area()[std::size_t(j)] / quad.phi_count() * std::abs(e.D(j, m) - iso.ndf.ndf[std::size_t(j)]);
    EXPECT_LT(diff, 1e-3) << to_string(smith);
    EXPECT_NEAR(e.eigenvalue, iso.eigenvalue, 1e-3 * iso.eigenvalue) << to_string(smith);
    const AnisotropicAlpha a = alpha_ggx_2d(e.ndf, quad);
    const double alpha = alpha_ggx_from_moments(iso.ndf, quad.base());
    EXPECT_NEAR(a.alpha_x, alpha, 1e-3 * alpha) << to_string(smith);
    EXPECT_NEAR(a.alpha_y, alpha, 1e-3 * alpha) << to_string(smith);
  }
}

class Anisotropic : public ::testing::TestWithParam<AnisotropicCase> {};

TEST_P(Anisotropic, PrincipalAlphasAndAngleComeBack) {
  const Quadrature2D quad(90, 64);
  const AnisotropicError e = measure_anisotropic(GetParam(), quad);
  ASSERT_TRUE(e.problem.empty()) << e.problem;
  EXPECT_NEAR(e.eigenvalue, 1.0, 0.01);  // F = 1
  EXPECT_LT(std::abs(e.alpha_x_relative), 0.01);
  EXPECT_LT(std::abs(e.alpha_y_relative), 0.01);
  EXPECT_LT(std::abs(e.angle_degrees), 0.5);
  EXPECT_LT(e.ndf_l1, 0.01);  // D itself at the grid's nodes, projected-area weighted
}

INSTANTIATE_TEST_SUITE_P(Extract2D, Anisotropic, ::testing::ValuesIn(dense_anisotropic_cases()));

TEST(Extract2D, BadInputsSayWhy) {
  const Quadrature2D quad(16, 8);
  Backscatter2D wrong;
  wrong.slices.resize(3);
  EXPECT_NE(extract_ndf_2d(wrong, quad, {}).problem.find("3 azimuthal slices"), std::string::npos);
  Backscatter2D zero;
  for (int m = 0; m < 8; ++m) zero.slices.push_back({{0.0, 0.5, 1.0}, {0.0, 0.0, 0.0}});
  EXPECT_NE(extract_ndf_2d(zero, quad, {}).problem.find("no back-scattered signal"), std::string::npos);
  EXPECT_THROW(Quadrature2D(16, 7), Error);
}

}  // namespace
}  // namespace facetfit
