// The reference renderer against answers known in closed form: a Lambertian and a white GGX sphere in a
// uniform environment, the same image whatever the passes, tiles and ray streams, the multiple importance
// sampling of light and BRDF samples, and the environment map's importance sampling.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "core/piecewise_constant.h"
#include "model/analytic.h"
#include "render/environment.h"
#include "render/mis.h"
#include "render/renderer.h"
#include "render/scene.h"
#include "render_fixtures.h"
#include "test_util.h"

namespace facetfit {
namespace {

// A sphere of `m` filling most of a small image, under a uniform environment of radiance 1.
SceneDesc furnace(const MaterialDesc& m, int spp = 64) {
  SceneDesc s = default_scene(m);
  s.camera.position = Vec3(0, 0, 4);
  s.camera.width = s.camera.height = 32;
  s.environment.kind = EnvironmentDesc::Kind::constant;
  s.environment.constant = Rgb(1.0);
  s.spp = spp;
  return s;
}

TEST(Render, LambertianSphereInAConstantEnvironmentIsItsAlbedo) {
  MaterialDesc m;
  m.type = "lambert";
  m.albedo = Rgb(0.8, 0.5, 0.2);
  const RenderedImage img = render(furnace(m, 64));
  // Unbiased: the mean over the sphere is the albedo; each pixel is within its Monte Carlo noise.
  int covered = 0;
  Rgb mean(0.0);
  for (int p = 0; p < img.width * img.height; ++p) {
    const float* px = img.rgba.data() + p * 4;
    if (px[3] < 1.0f) continue;  // edge pixels mix in the background
    ++covered;
    mean += Rgb(px[0], px[1], px[2]);
    EXPECT_NEAR(px[0], 0.8, 0.1);
  }
  ASSERT_GT(covered, 300);
  mean /= double(covered);
  EXPECT_NEAR(mean.r, 0.8, 0.004);
  EXPECT_NEAR(mean.g, 0.5, 0.0025);
  EXPECT_NEAR(mean.b, 0.2, 0.001);
}

TEST(Render, WhiteFurnaceNeverExceedsOneAndMatchesTheAlbedo) {
  // A white (F = 1) GGX sphere: each pixel is the model's directional albedo at its view angle (< 1).
  MaterialDesc m;
  m.type = "ggx";
  m.alpha = 0.5;
  m.f0 = m.f82 = Rgb(1.0);
  const RenderedImage img = render(furnace(m, 1024));
  const MicrofacetBrdf brdf(Ndf::isotropic(NdfType::ggx, 0.5), Smith::correlated, Fresnel::one());
  // Albedo at a view angle by quadrature, for comparison at the centre pixel (normal view).
  const auto albedo = [&](double cos_o) {
    const Vec3 o(std::sqrt(1 - cos_o * cos_o), 0, cos_o);
    double sum = 0.0;
    const int n = 400;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        const double c = (a + 0.5) / n, s = std::sqrt(1 - c * c), phi = (b + 0.5) / n * 2 * kPi;
        sum += brdf.eval(o, Vec3(s * std::cos(phi), s * std::sin(phi), c))->g * c / (n * n) * 2 * kPi;
      }
    return sum;
  };
  double max_value = 0.0;
  for (int p = 0; p < img.width * img.height; ++p)
    if (img.rgba[std::size_t(p) * 4 + 3] >= 1.0f) max_value = std::max(max_value, double(img.rgba[std::size_t(p) * 4 + 1]));
  EXPECT_LE(max_value, 1.0 + 0.02);
  // The central 4 x 4 pixels see the sphere within 6 degrees of its normal, where the albedo changes
  // by less than 0.1%: their mean averages the noise down (about 0.002).
  double centre = 0.0;
  for (int y = 14; y < 18; ++y)
    for (int x = 14; x < 18; ++x) centre += img.rgba[(std::size_t(y) * 32 + x) * 4 + 1] / 16.0;
  EXPECT_NEAR(centre, albedo(0.997), 0.006);
}

TEST(Render, SameSceneSameImage) {
  MaterialDesc m;
  m.type = "ggx";
  m.alpha = 0.2;
  SceneDesc s = default_scene(m);
  s.camera.width = s.camera.height = 24;
  s.spp = 8;
  RenderSettings one_pass;
  one_pass.passes = 1;
  const RenderedImage a = render(s), b = render(s, one_pass);
  EXPECT_EQ(a.rgba, b.rgba);  // passes, tiles and threads do not change the per-pixel sequences
}

// Everything that makes shadow rays: an environment (the sky's map: light and BRDF samples; or a constant
// one: BRDF samples alone), both kinds of light, a plane the spheres
// shadow, and the proposals of every kind (closed-form GGX, tabulated Beckmann, a measured table, a LUT
// whose frame follows a tangent).
class RayStreams : public ::testing::TestWithParam<const char*> {};

TEST_P(RayStreams, AndOneRayAtATimeGiveTheSameImage) {
  test::TempDir dir;
  test::write_gold_lut(dir.file("gold.exr"));
  const SceneDesc s = parse_scene_text(std::string(R"({
    "camera": {"position": [0, 1.5, 5], "look_at": [0, 0.3, 0], "fov": 40, "width": 40, "height": 30},
    "render": {"spp": 6, "seed": 3},
    "environment": )") + GetParam() + R"(,
    "lights": [{"type": "directional", "direction": [0.3, 1, 0.5], "irradiance": [2, 2, 2]},
               {"type": "point", "position": [-2, 3, 1], "intensity": [5, 4, 3]}],
    "materials": {"g": {"type": "ggx", "alpha": 0.2, "f0": [0.9, 0.6, 0.3]},
                  "b": {"type": "beckmann", "alpha": 0.4},
                  "m": {"type": "measured", "file": "builtin:red-plastic"},
                  "l": {"type": "lut", "file": ")" + dir.file("gold.exr") + R"(", "tangent": [0.3, 1, 0.2]},
                  "floor": {"type": "lambert", "albedo": [0.5, 0.5, 0.5]}},
    "objects": [{"type": "sphere", "center": [-1.2, 0.5, 0], "radius": 0.5, "material": "g"},
                {"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "material": "b"},
                {"type": "sphere", "center": [1.2, 0.5, 0], "radius": 0.5, "material": "m"},
                {"type": "sphere", "center": [-0.6, 1.5, -0.8], "radius": 0.4, "material": "l"},
                {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "size": 8, "material": "floor"}]
  })", "streams.json", ".");
  RenderSettings one_ray;
  one_ray.ray_streams = false;
  const RenderedImage a = render(s), b = render(s, one_ray);
  ASSERT_EQ(a.rgba.size(), b.rgba.size());
  double worst = 0.0, mean = 0.0, coverage = 0.0, lit = 0.0;
  int beyond = 0;
  for (std::size_t k = 0; k < a.rgba.size(); ++k) {
    const double d = std::abs(double(a.rgba[k]) - double(b.rgba[k])) / std::max(1.0, std::abs(double(b.rgba[k])));
    worst = std::max(worst, d);
    mean += d / double(a.rgba.size());
    beyond += d > 1e-5;
    if (k % 4 == 3) coverage += b.rgba[k];
    else lit += b.rgba[k];
  }
  // Float rounding: the same numbers through the same shading code; Embree's stream kernels compute the hit
  // distance (in float) with other instructions than its one-ray kernel, which moves the shading point by
  // ~1e-7. Which kernels run depends on the CPU: with AVX-512 the worst value moved by 1.2e-5; with
  // AVX2 (an AMD EPYC) one pixel of 1,200 moved by 5.6e-4, a sample there landing on the other side of
  // a discontinuity, while the mean moved by 2.4e-7. So: the mean at rounding level, a handful of values
  // beyond 1e-5, none beyond 1e-3.
  std::printf("[ streams ] mean relative difference %.2e, worst %.2e, %d of %zu values beyond 1e-5\n", mean, worst, beyond, a.rgba.size());
  EXPECT_LT(mean, 1e-6);
  EXPECT_LE(beyond, int(a.rgba.size() / 400));
  EXPECT_LT(worst, 1e-3);
  EXPECT_GT(coverage, 0.5 * 40 * 30);  // the scene is in view and lit: the comparison is not of empty images
  EXPECT_GT(lit, 0.0);
}

INSTANTIATE_TEST_SUITE_P(Render, RayStreams, ::testing::Values(R"({"builtin": "sky"})", R"({"constant": [0.3, 0.3, 0.3]})"));

// A constant environment is lit by the BRDF sample alone, a map by a light sample and a BRDF sample
// weighted by multiple importance sampling (render/integrator.cpp): two estimators of the same integral.
// A map whose every pixel is the constant must then give the same sphere, to the noise, for every kind of
// model: closed-form GGX, tabulated Beckmann, Lambert, a measured table under its fitted proposal, a LUT,
// and a stretched LUT (shaded one pair at a time).
TEST(Render, AConstantEnvironmentAndTheSameMapGiveTheSameSphere) {
  test::TempDir dir;
  test::write_gold_lut(dir.file("gold.exr"));
  test::write_texture(dir.file("flat.exr"), 32, 16, [](int, int) { return Rgb(0.3, 0.25, 0.2); });
  const std::string materials[] = {R"({"type": "ggx", "alpha": 0.2, "f0": [0.9, 0.6, 0.3]})", R"({"type": "beckmann", "alpha": 0.4, "f0": [0.8, 0.8, 0.8]})",
                                   R"({"type": "lambert", "albedo": [0.7, 0.5, 0.3]})", R"({"type": "measured", "file": "builtin:red-plastic"})",
                                   R"({"type": "lut", "file": "gold.exr"})", R"({"type": "lut", "file": "gold.exr", "stretch": [3, 0.5]})"};
  double worst = 0.0;
  for (const std::string& material : materials) {
    const auto sphere = [&](const std::string& environment) {
      const RenderedImage image = render(parse_scene_text(R"({"camera": {"position": [0, 0.6, 4], "look_at": [0, 0, 0], "fov": 30,
        "width": 48, "height": 48}, "render": {"spp": 64, "seed": 5}, "environment": )" + environment + R"(,
        "materials": {"m": )" + material + R"(}, "objects": [{"type": "sphere", "material": "m"}]})", "s.json", dir.path().string()));
      double sum = 0.0;
      int covered = 0;
      for (std::size_t p = 0; p < image.rgba.size(); p += 4)
        if (image.rgba[p + 3] > 0.999f) sum += double(image.rgba[p]) + image.rgba[p + 1] + image.rgba[p + 2], ++covered;
      EXPECT_GT(covered, 600) << material;
      return sum / covered;
    };
    const double by_brdf = sphere(R"({"constant": [0.3, 0.25, 0.2]})"), by_both = sphere(R"({"file": "flat.exr"})");
    ASSERT_GT(by_both, 0.05) << material;
    worst = std::max(worst, std::abs(by_brdf / by_both - 1.0));
    // Each mean is over ~900 pixels of 64 samples: a few 1e-3 of noise; a lost or doubled weight is far more.
    EXPECT_NEAR(by_brdf / by_both, 1.0, 0.01) << material << ": BRDF samples alone " << by_brdf << ", with light samples " << by_both;
  }
  std::printf("[ constant ] worst relative difference of the sphere's mean %.2e\n", worst);
}

// The integrator's MIS factor (render/mis.h): cos w(p, q) / p by the power heuristic, as the two-sample sum
// needs it, and finite where p^2 + q^2 underflows (the one-ray path gave 0 / 0 there; the lanes did not).
TEST(Mis, PowerHeuristicFactorStaysFiniteWhereTheSquaresUnderflow) {
  const auto reference = [](double cos, double p, double q) { return cos * (p * p / (p * p + q * q)) / p; };
  for (const auto& [p, q] : {std::pair{1.0, 1.0}, {0.3, 2.0}, {5.0, 1e-3}, {1e-100, 1e-100}, {2.0, 0.0}})
    EXPECT_NEAR(power_heuristic_factor(0.7, p, q), reference(0.7, p, q), 1e-14 * reference(0.7, p, q)) << p << " " << q;
  EXPECT_TRUE(std::isnan(reference(0.7, 1e-170, 1e-170)));  // the heuristic as written
  EXPECT_NEAR(power_heuristic_factor(0.7, 1e-170, 1e-170), 0.7 / 2e-170, 1e-12 * (0.7 / 2e-170));
  EXPECT_NEAR(power_heuristic_factor(0.7, 1e-170, 3e-170), 0.7 / (1e-170 + 9e-170), 1e-12 * (0.7 / 1e-169));
  EXPECT_EQ(power_heuristic_factor(0.7, 0.0, 1.0), 0.0);
  EXPECT_EQ(power_heuristic_factor(0.7, 0.0, 0.0), 0.0);
}

TEST(PiecewiseConstant2D, DrawsCellsInProportionToTheirWeightsAndReportsTheirDensity) {
  // 3 x 2 cells, one empty, one empty row: counts within 1% of the weights' shares, density = share x 6.
  const std::vector<double> w = {1.0, 0.0, 3.0, 0.0, 0.0, 0.0};
  const PiecewiseConstant2D d(w, 3, 2);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<int> count(6, 0);
  const int n = 200000;
  for (int k = 0; k < n; ++k) {
    const auto s = d.sample(u(rng), u(rng));
    ASSERT_EQ(int(s.u * 3), s.x);
    ASSERT_EQ(int(s.v * 2), s.y);
    ++count[std::size_t(s.y * 3 + s.x)];
  }
  EXPECT_NEAR(count[0] / double(n), 0.25, 0.01);
  EXPECT_NEAR(count[2] / double(n), 0.75, 0.01);
  EXPECT_EQ(count[1] + count[3] + count[4] + count[5], 0);
  EXPECT_DOUBLE_EQ(d.pdf(0, 0), 0.25 * 6);
  EXPECT_DOUBLE_EQ(d.pdf(2, 0), 0.75 * 6);
}

TEST(Environment, ImportanceSamplingAgreesWithItsPdf) {
  const Environment sky = Environment::sky(128);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // The pdf integrates to one over the sphere (uniform-sphere estimate) ...
  double integral = 0.0, flux_uniform = 0.0, flux_sampled = 0.0;
  const int n = 400000;
  for (int k = 0; k < n; ++k) {
    const double z = 1.0 - 2.0 * u(rng), r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 2.0 * kPi * u(rng);
    const Vec3 d(r * std::cos(phi), z, r * std::sin(phi));
    integral += sky.pdf(d) * 4.0 * kPi / n;
    flux_uniform += luminance(sky.radiance(d)) * 4.0 * kPi / n;
    // ... the drawn pixel's pdf is the pdf of its direction, and importance sampling is unbiased.
    const Environment::Sample s = sky.sample(u(rng), u(rng));
    const Environment::Sample l = sky.lookup(s.d);
    EXPECT_NEAR(s.pdf, l.pdf, 1e-9 * l.pdf + 1e-12);
    flux_sampled += luminance(s.radiance) / s.pdf / n;
  }
  EXPECT_NEAR(integral, 1.0, 0.01);
  EXPECT_NEAR(flux_sampled, flux_uniform, 0.03 * flux_uniform);
}

}  // namespace
}  // namespace facetfit
