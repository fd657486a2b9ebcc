// CIEDE2000 against the published test data, and the display chain from scene-linear pixels to CIELAB.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <random>
#include <thread>
#include <vector>

#include "color/ciede2000.h"
#include "color/display.h"

namespace facetfit {
namespace {

struct SharmaPair {
  Lab x, y;
  double delta_e;  // as published, 4 decimals
};

// Sharma, Wu and Dalal (2005), Table 1: the 34 pairs, in order.
const SharmaPair kSharma[34] = {
    {{50.0000, 2.6772, -79.7751}, {50.0000, 0.0000, -82.7485}, 2.0425},
    {{50.0000, 3.1571, -77.2803}, {50.0000, 0.0000, -82.7485}, 2.8615},
    {{50.0000, 2.8361, -74.0200}, {50.0000, 0.0000, -82.7485}, 3.4412},
    {{50.0000, -1.3802, -84.2814}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, -1.1848, -84.8006}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, -0.9009, -85.5211}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, 0.0000, 0.0000}, {50.0000, -1.0000, 2.0000}, 2.3669},
    {{50.0000, -1.0000, 2.0000}, {50.0000, 0.0000, 0.0000}, 2.3669},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0009}, 7.1792},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0010}, 7.1792},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0011}, 7.2195},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0012}, 7.2195},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0009, -2.4900}, 4.8045},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0010, -2.4900}, 4.8045},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0011, -2.4900}, 4.7461},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 0.0000, -2.5000}, 4.3065},
    {{50.0000, 2.5000, 0.0000}, {73.0000, 25.0000, -18.0000}, 27.1492},
    {{50.0000, 2.5000, 0.0000}, {61.0000, -5.0000, 29.0000}, 22.8977},
    {{50.0000, 2.5000, 0.0000}, {56.0000, -27.0000, -3.0000}, 31.9030},
    {{50.0000, 2.5000, 0.0000}, {58.0000, 24.0000, 15.0000}, 19.4535},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.1736, 0.5854}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.2972, 0.0000}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 1.8634, 0.5757}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.2592, 0.3350}, 1.0000},
    {{60.2574, -34.0099, 36.2677}, {60.4626, -34.1751, 39.4387}, 1.2644},
    {{63.0109, -31.0961, -5.8663}, {62.8187, -29.7946, -4.0864}, 1.2630},
    {{61.2901, 3.7196, -5.3901}, {61.4292, 2.2480, -4.9620}, 1.8731},
    {{35.0831, -44.1164, 3.7933}, {35.0232, -40.0716, 1.5901}, 1.8645},
    {{22.7233, 20.0904, -46.6940}, {23.0331, 14.9730, -42.5619}, 2.0373},
    {{36.4612, 47.8580, 18.3852}, {36.2715, 50.5065, 21.2231}, 1.4146},
    {{90.8027, -2.0831, 1.4410}, {91.1528, -1.6435, 0.0447}, 1.4441},
    {{90.9257, -0.5406, -0.9208}, {88.6381, -0.8985, -0.7239}, 1.5381},
    {{6.7747, -0.2908, -2.4247}, {5.8714, -0.0985, -2.2286}, 0.6377},
    {{2.0776, 0.0795, -1.1350}, {0.9033, -0.0636, -0.5514}, 0.9082},
};

// The published values are rounded to 4 decimals: within 0.5e-4 of them, both ways round.
TEST(Ciede2000, SharmaTable) {
  double worst = 0;
  for (int i = 0; i < 34; ++i) {
    const SharmaPair& p = kSharma[i];
    const double forward = ciede2000(p.x, p.y), backward = ciede2000(p.y, p.x);
    EXPECT_NEAR(forward, p.delta_e, 0.5e-4) << "pair " << i + 1;
    EXPECT_NEAR(backward, p.delta_e, 0.5e-4) << "pair " << i + 1 << " reversed";
    worst = std::max({worst, std::abs(forward - p.delta_e), std::abs(backward - p.delta_e)});
  }
  RecordProperty("max_error", std::to_string(worst));
  std::printf("Sharma et al. 34 pairs: max |error| %.2e\n", worst);
}

TEST(Ciede2000, SymmetricAndZeroForEqualColours) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> L(0, 100), ab(-128, 128);
  for (int i = 0; i < 2000; ++i) {
    const Lab x{L(rng), ab(rng), ab(rng)}, y{L(rng), ab(rng), ab(rng)};
    EXPECT_NEAR(ciede2000(x, y), ciede2000(y, x), 1e-12);
    EXPECT_EQ(ciede2000(x, x), 0.0);
    EXPECT_GT(ciede2000(x, y), 0.0);
  }
  EXPECT_EQ(ciede2000({50, 0, 0}, {50, 0, 0}), 0.0);
}

TEST(Ciede2000, ParametricFactorsDivideTheirTerm) {
  // Neutral colours differ in lightness only: kL divides the whole difference.
  const Lab grey{40, 0, 0}, lighter{60, 0, 0};
  EXPECT_NEAR(ciede2000(grey, lighter, 2, 1, 1), 0.5 * ciede2000(grey, lighter), 1e-12);
  EXPECT_NEAR(ciede2000(grey, lighter, 1, 3, 3), ciede2000(grey, lighter), 1e-12);
}

// Expected values below: the paper's equations evaluated in 40-digit arithmetic (mpmath), with the
// hues placed exactly 180 degrees apart.

// Hues 0 and 180 (opposite on the a' axis): |h1' - h2'| = 180 takes the paper's first branch, mean hue
// (0 + 180) / 2 = 90 and dh' = +180; reading the tie as "> 180" would give a mean hue of 270.
TEST(Ciede2000, HueTieOnTheAAxis) {
  const Lab x{50, 10, 0}, y{50, -10, 0};
  EXPECT_NEAR(ciede2000(x, y), 26.027273663502041, 1e-9);
  EXPECT_NEAR(ciede2000(y, x), 26.027273663502041, 1e-9);
}

// Hues 90 and 270: mean hue 180, not 0.
TEST(Ciede2000, HueTieOnTheBAxis) {
  const Lab x{50, 0, 10}, y{50, 0, -10};
  EXPECT_NEAR(ciede2000(x, y), 17.440944584940469, 1e-9);
  EXPECT_NEAR(ciede2000(y, x), 17.440944584940469, 1e-9);
}

// A tie off the axes, where rounded degrees cannot be trusted to come out exactly 180 apart: y is -2x
// in (a, b), so a'2 = -2 a'1 and b2 = -2 b1 exactly. Hues 178.1 and 358.1, mean hue 268.1 (near the blue
// rotation term's peak, so the branch matters), chromas differ so the sign of dh' matters too.
TEST(Ciede2000, HueTieOffTheAxes) {
  const double a = 20 * std::cos(178 * kPi / 180), b = 20 * std::sin(178 * kPi / 180);
  const Lab x{50, a, b}, y{55, -2 * a, -2 * b};
  const double expected = 37.767650544610843;
  EXPECT_NEAR(ciede2000(x, y), expected, 1e-9);
  EXPECT_NEAR(ciede2000(y, x), expected, 1e-9);

  // The tie belongs to the side where |h1' - h2'| < 180: turning y a hair so that its hue comes closer
  // to x's is continuous with it; turning it the other way crosses into the other branch and jumps.
  const auto turned = [&](double degrees) {
    const double c = std::hypot(2 * a, 2 * b), h = std::atan2(-2 * b, -2 * a) + degrees * kPi / 180;
    return Lab{55, c * std::cos(h), c * std::sin(h)};
  };
  for (const double step : {1e-4, 1e-9}) {  // outside and inside the band decided by the cross product
    EXPECT_NEAR(ciede2000(x, turned(-step)), expected, 1e-3) << step;
    EXPECT_GT(std::abs(ciede2000(x, turned(+step)) - expected), 1.0) << step;
  }
}

// C'1 C'2 = 0: dh' = 0 and the mean hue is h1' + h2', not halved (here 306.3, in the blue rotation's
// range; halving it would give 153.2).
TEST(Ciede2000, ZeroChroma) {
  const Lab grey{50, 0, 0}, colour{60, 10, -20};
  EXPECT_NEAR(ciede2000(grey, colour), 18.529934752794379, 1e-9);
  EXPECT_NEAR(ciede2000(colour, grey), 18.529934752794379, 1e-9);
}

// ---- the display chain -----------------------------------------------------------------------------------

TEST(Display, MatrixFromTheChromaticities) {
  // Columns: the primaries' XYZ (Y = 1), scaled so that they add up to the white.
  const auto xyz = [](double x, double y) { return Vec3(x / y, 1, (1 - x - y) / y); };
  const glm::dmat3 primaries(xyz(0.64, 0.33), xyz(0.30, 0.60), xyz(0.15, 0.06));
  const Vec3 white = xyz(0.3127, 0.3290);
  const Vec3 scale = glm::inverse(primaries) * white;
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(kRec709ToXyz[i][k], primaries[k][i] * scale[k], 1e-10) << i << "," << k;
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(kD65White[i], white[i], 1e-15);
    EXPECT_NEAR(kRec709ToXyz[i][0] + kRec709ToXyz[i][1] + kRec709ToXyz[i][2], kD65White[i], 1e-9);
  }
}

TEST(Display, SrgbCurve) {
  EXPECT_NEAR(srgb_encode(0.18), 0.461356, 1e-6);
  EXPECT_NEAR(srgb_encode(1.0), 1.0, 1e-15);
  EXPECT_EQ(srgb_encode(0.0), 0.0);
  // Value and slope continuous at the joint (that is how OCIO places it).
  const double joint = 0.055 / 1.4, h = 1e-6;
  const double below = (srgb_decode(joint) - srgb_decode(joint - h)) / h;
  const double above = (srgb_decode(joint + h) - srgb_decode(joint)) / h;
  EXPECT_NEAR(below, above, 1e-5 * below);
  EXPECT_NEAR(srgb_decode(joint + h) - srgb_decode(joint - h), h * (below + above), 1e-13);  // no jump
  // Within 1e-6 of the IEC 61966-2-1 decoding everywhere.
  for (int i = 0; i <= 1000; ++i) {
    const double v = i / 1000.0;
    const double iec = v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
    EXPECT_NEAR(srgb_decode(v), iec, 1e-6) << v;
    EXPECT_NEAR(srgb_encode(srgb_decode(v)), v, 1e-12) << v;
  }
}

TEST(Display, OcioMatchesTheCurveAndClamps) {
  const DisplayTransform display;
  std::vector<float> rgb;
  for (int i = 0; i <= 1000; ++i) rgb.push_back(float(i / 1000.0));
  rgb.push_back(0.0f);
  rgb.push_back(0.0f);  // 1001 values + 2: whole pixels
  std::vector<float> out = rgb;
  display.to_display(out.data(), out.size() / 3);
  for (std::size_t i = 0; i < rgb.size(); ++i) EXPECT_NEAR(out[i], srgb_encode(rgb[i]), 1e-6) << rgb[i];

  EXPECT_NEAR(display.to_display(Rgb(0.18)).r, 0.461356, 1e-6);
  const Rgb clamped = display.to_display(Rgb(2.0, -0.5, std::nan("")));
  EXPECT_NEAR(clamped.r, 1.0, 1e-6);
  EXPECT_EQ(clamped.g, 0.0);
  EXPECT_EQ(clamped.b, 0.0);
  const Rgb infinite = display.to_display(Rgb(INFINITY, -INFINITY, 0.5));
  EXPECT_NEAR(infinite.r, 1.0, 1e-6);
  EXPECT_EQ(infinite.g, 0.0);
}

TEST(Display, KnownLab) {
  const DisplayTransform display;
  const Lab white = display.linear_to_lab(Rgb(1.0));
  EXPECT_NEAR(white.L, 100, 1e-4);
  EXPECT_NEAR(white.a, 0, 1e-4);
  EXPECT_NEAR(white.b, 0, 1e-4);
  const Lab black = display.linear_to_lab(Rgb(0.0));
  EXPECT_NEAR(black.L, 0, 1e-12);
  EXPECT_NEAR(black.a, 0, 1e-12);
  EXPECT_NEAR(black.b, 0, 1e-12);
  // Middle grey: Y = 0.18, L* = 116 0.18^(1/3) - 16 = 49.496.
  const Lab grey = display.linear_to_lab(Rgb(0.18));
  EXPECT_NEAR(grey.L, 116 * std::cbrt(0.18) - 16, 1e-4);
  EXPECT_NEAR(grey.a, 0, 1e-4);
  EXPECT_NEAR(grey.b, 0, 1e-4);
  // The sRGB primaries' CIELAB as Lindbloom's sRGB matrix (0.4124564 ...) and white (0.95047, 1, 1.08883)
  // give them; the matrix derived here from the chromaticities moves them by less than 0.01.
  const struct {
    Rgb rgb;
    Lab lab;
  } primaries[] = {{Rgb(1, 0, 0), {53.2408, 80.0925, 67.2032}},
                   {Rgb(0, 1, 0), {87.7347, -86.1827, 83.1793}},
                   {Rgb(0, 0, 1), {32.2970, 79.1875, -107.8602}}};
  for (const auto& p : primaries) {
    const Lab lab = display.linear_to_lab(p.rgb);
    EXPECT_NEAR(lab.L, p.lab.L, 0.01);
    EXPECT_NEAR(lab.a, p.lab.a, 0.01);
    EXPECT_NEAR(lab.b, p.lab.b, 0.01);
  }
  // Past white, the display clips: brighter than 1 is white.
  const Lab over = display.linear_to_lab(Rgb(4.0, 1.5, 1.0));
  EXPECT_NEAR(ciede2000(over, white), 0.0, 1e-4);
}

// One DisplayTransform shared by threads gives each the same answer as alone.
TEST(Display, ConcurrentUse) {
  const DisplayTransform display;
  std::vector<float> reference(3 * 4096);
  for (std::size_t i = 0; i < reference.size(); ++i) reference[i] = float(i % 1500) / 1000.0f;
  std::vector<float> expected = reference;
  display.to_display(expected.data(), expected.size() / 3);
  std::vector<std::vector<float>> results(4, reference);
  std::vector<std::thread> threads;
  for (auto& r : results) threads.emplace_back([&display, &r] { display.to_display(r.data(), r.size() / 3); });
  for (auto& t : threads) t.join();
  for (const auto& r : results) EXPECT_EQ(r, expected);
}

}  // namespace
}  // namespace facetfit
