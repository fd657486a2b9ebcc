// UTIA anisotropic BRDF files (io/utia.h): the writer and reader are inverse, the lookup is the
// database readers' quadrilinear one, bad files get one line, and an anisotropic GGX written as UTIA
// comes back from the 2D extraction (fit/extract_2d.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <random>

#include "core/error.h"
#include "fit/extract_2d.h"
#include "io/utia.h"
#include "model/analytic.h"
#include "support/ground_truth.h"
#include "test_util.h"

namespace facetfit {
namespace {

TEST(Utia, EncodingRoundTripsAndKeepsNegatives) {
  for (double f : {-0.5, -1e-3, 0.0, 1e-4, 0.01, 0.29, 0.2904, 0.3, 1.0, 12.5, 100.0, 400.0})
    EXPECT_NEAR(UtiaBrdf::decode(UtiaBrdf::encode(f)), f, 1e-9 * std::max(1.0, std::abs(f))) << f;
  // The decoding's branches leave a gap of 4e-4 relative at 0.0375 (f 0.29025-0.29036 / sr): its edge.
  EXPECT_NEAR(UtiaBrdf::decode(UtiaBrdf::encode(0.29027)), 0.29027, 4e-4 * 0.29027);
  EXPECT_NEAR(UtiaBrdf::decode(1.0), 100.0, 1e-12);  // full scale: 100 / sr
  EXPECT_LT(UtiaBrdf::decode(-0.01), 0.0);
}

TEST(Utia, WriteReadAndLookUp) {
  test::TempDir dir;
  const MicrofacetBrdf ggx(Ndf{NdfType::ggx, 0.4, 0.2}, Smith::correlated, Fresnel::schlick(Rgb(0.9, 0.6, 0.3)));
  const RotatedBrdf turned(ggx, 0.5);
  UtiaBrdf::tabulate(turned).write(dir.file("a.bin"));
  EXPECT_EQ(std::filesystem::file_size(dir.file("a.bin")), UtiaBrdf::kFileBytes);
  const UtiaBrdf read = UtiaBrdf::read(dir.file("a.bin"));
  // At the nodes: the BRDF itself.
  for (int ti : {0, 2, 5})
    for (int pv : {0, 7, 47}) {
      const Vec3 i = spherical_direction(ti * 15.0 * kPi / 180.0, 30.0 * kPi / 180.0);
      const Vec3 o = spherical_direction(45.0 * kPi / 180.0, pv * 7.5 * kPi / 180.0);
      const Rgb want = *turned.eval(o, i), got = *read.eval(o, i);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-9 * std::max(1.0, want[c]));
    }
  // Between them: the mean of the two neighbours halfway along one azimuth, periodic across 360 degrees.
  const Vec3 o = spherical_direction(30.0 * kPi / 180.0, 0.0), i = spherical_direction(45.0 * kPi / 180.0, 358.5 * kPi / 180.0);
  const Rgb a = read.node(3, 47, 2, 0), b = read.node(3, 0, 2, 0), mid = *read.eval(o, i);
  const double t = (358.5 - 352.5) / 7.5;
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(mid[c], (1.0 - t) * a[c] + t * b[c], 1e-9);
}

TEST(Utia, BadFilesGetOneLine) {
  test::TempDir dir;
  test::write_bytes(dir.file("short.bin"), std::string(100, '\0'));
  EXPECT_NE(test::error_of([&] { UtiaBrdf::read(dir.file("short.bin")); }).find("size is 100 bytes"), std::string::npos);
  EXPECT_NE(test::error_of([&] { UtiaBrdf::read(dir.file("missing.bin")); }).find("no such file"), std::string::npos);
  std::string bytes(UtiaBrdf::kFileBytes, '\0');
  const double nan = std::nan("");
  std::memcpy(&bytes[800], &nan, sizeof nan);
  test::write_bytes(dir.file("nan.bin"), bytes);
  EXPECT_NE(test::error_of([&] { UtiaBrdf::read(dir.file("nan.bin")); }).find("byte offset 800"), std::string::npos);
  // Finite in the file, infinite once decoded (x^2.4 overflows): refused the same way.
  std::string huge(UtiaBrdf::kFileBytes, '\0');
  const double big = 1e200;
  std::memcpy(&huge[1600], &big, sizeof big);
  test::write_bytes(dir.file("huge.bin"), huge);
  EXPECT_NE(test::error_of([&] { UtiaBrdf::read(dir.file("huge.bin")); }).find("byte offset 1600 is not a finite number"), std::string::npos);
  EXPECT_NE(test::error_of([&] { UtiaBrdf::read("/dev/zero"); }).find("not a regular file"), std::string::npos);
}

// The bar: alpha_x and alpha_y within 3% for alpha >= 0.2 from the 15-degree grid.
class UtiaGroundTruth : public ::testing::TestWithParam<AnisotropicCase> {};

TEST_P(UtiaGroundTruth, AlphasComeBackThroughTheFile) {
  test::TempDir dir;
  const Quadrature2D quad(90, 48);
  const AnisotropicError e = measure_anisotropic(GetParam(), quad, AnisotropicInput::utia, dir.file("m.bin"));
  ASSERT_TRUE(e.problem.empty()) << e.problem;
  EXPECT_LT(std::abs(e.alpha_x_relative), 0.03);
  EXPECT_LT(std::abs(e.alpha_y_relative), 0.03);
  EXPECT_LT(std::abs(e.angle_degrees), 2.0);
}

INSTANTIATE_TEST_SUITE_P(Utia, UtiaGroundTruth,
                         ::testing::ValuesIn(utia_anisotropic_cases()));

TEST(Utia, AzimuthalMeanIsTheMeanOverTurnsByTheFilesStep) {
  const MicrofacetBrdf aniso(Ndf{NdfType::ggx, 0.4, 0.15}, Smith::correlated, Fresnel::schlick(Rgb(0.9, 0.6, 0.3)));
  const UtiaBrdf file = UtiaBrdf::tabulate(RotatedBrdf(aniso, 0.4));
  const UtiaBrdf mean = file.azimuthal_mean();
  std::mt19937 rng(3);
  for (int k = 0; k < 100; ++k) {
    const Vec3 o = test::random_direction(rng), i = test::random_direction(rng);
    Rgb want(0.0);
    for (int t = 0; t < UtiaBrdf::kPhi; ++t) {
      // Both directions turned by t steps (RotatedBrdf turns them by minus its angle).
      want += *RotatedBrdf(file, -t * UtiaBrdf::kPhiStep * kPi / 180.0).eval(o, i) / double(UtiaBrdf::kPhi);
    }
    const Rgb got = *mean.eval(o, i);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-9 * std::max(1.0, std::abs(want[c])));
    // Isotropic: a turn of both directions changes nothing.
    const Vec3 o2(-o.y, o.x, o.z), i2(-i.y, i.x, i.z);
    EXPECT_NEAR(mean.eval(o2, i2)->g, got.g, 1e-9 * std::max(1.0, got.g));
  }
}

}  // namespace
}  // namespace facetfit
