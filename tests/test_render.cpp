// The reference renderer against answers known in closed form.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <iostream>
#include <limits>
#include <random>
#include <sstream>

#include "fit/fit.h"
#include "io/image_file.h"
#include "io/input.h"
#include "io/utia.h"
#include "lut/lut.h"
#include "model/analytic.h"
#include "model/tabulated.h"
#include "model/visible_slopes.h"
#include "model/parametric.h"
#include "model/proposal.h"
#include "core/frame.h"
#include "render/mis.h"
#include "render/renderer.h"
#include "render/camera_batch.h"
#include "render/environment.h"
#include "render/materials.h"
#include "render/ggx_batch.h"
#include "render/merl_batch.h"
#include "render/shading.h"
#include "render/sphere_batch.h"
#include "render/tabulated_batch.h"
#include "render/texture.h"
#include "render/tracer.h"
#include "render/wavefront.h"
#include "support/tensor_file.h"
#include "test_util.h"

namespace facetfit {
namespace {

// The paper's fit of the built-in gold GGX 0.15, baked with sampling tables.
void write_gold_lut(const std::string& path) {
  const Fitter fitter{FitOptions::paper()};
  write_lut(path, make_lut(fitter.fit(load_table("builtin:gold-ggx-0.15")), fitter.quadrature(), "builtin:gold-ggx-0.15", "x", 0.02, true));
}

// A float RGB image of `width` x `height` with value(x, y) at pixel (x, y), row 0 at the top.
void write_texture(const std::string& path, int width, int height, const std::function<Rgb(int, int)>& value) {
  std::vector<float> px;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const Rgb v = value(x, y);
      px.insert(px.end(), {float(v.r), float(v.g), float(v.b)});
    }
  write_image_atomic(path, ImageSpec(width, height, {"R", "G", "B"}), px.data());
}

// A Fresnel curve whose three channels differ and vary along theta_d, for the SIMD kernels' tests.
FresnelCurve coloured_curve() {
  FresnelCurve curve;
  for (int j = 0; j < FresnelCurve::kSize; ++j) curve.value[std::size_t(j)] = Rgb(0.9 - 0.005 * j, 0.5 + 0.004 * j, 0.2 + 0.001 * j * j / 90.0);
  return curve;
}

// A direction for the SIMD kernels' tests: cos(theta) uniform on [-0.95, 1.05] (so about half the pairs
// have one direction below the horizon), a fraction `grazing` of them on the horizon (cos(theta) 1e-7).
// With `underflow`, a quarter of those directions have z = 1e-170 (z^2 underflows), a quarter a denormal z
// and a quarter lie within 1e-160 of the normal (x^2 + y^2 a denormal): where the AVX-512 kernels'
// reciprocals and inverse square roots leave their estimates and must give what the division gives.
Vec3 lane_test_direction(std::mt19937_64& rng, double grazing, bool underflow = false) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double z = 2.0 * u(rng) - 0.95, phi = 2.0 * kPi * u(rng), s = std::sqrt(std::max(0.0, 1.0 - z * z));
  if (u(rng) >= grazing) return Vec3(s * std::cos(phi), s * std::sin(phi), z);
  const int kind = underflow ? int(4.0 * u(rng)) % 4 : 0;
  if (kind == 3) return Vec3(1e-160 * std::cos(phi), 1e-160 * std::sin(phi), 1.0);
  const double heights[] = {1e-7, 1e-170, 1e-310};
  return glm::normalize(Vec3(std::cos(phi), std::sin(phi), heights[kind]));
}

// x rounded to single precision, the lanes' of the tabulated lobe (render/tabulated_batch.h): their
// inputs as they see them.
double single(double x) { return double(float(x)); }
Vec3 single(const Vec3& v) { return Vec3(single(v.x), single(v.y), single(v.z)); }

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

TEST(Tracer, SphereRootsStayAccurateFarAwayAndAtGrazingAngles) {
  const Vec3 c(0.0, 0.0, 0.0);
  // Far away: 1e6 units off, the root is 1e6 - 1 to a relative 1e-12 (b^2 - ac would lose half the digits).
  EXPECT_NEAR(intersect_sphere(c, 1.0, Ray{Vec3(0, 0, 1e6), Vec3(0, 0, -1)}), 1e6 - 1.0, 1e-6);
  // An unnormalized direction: t is in its units.
  EXPECT_NEAR(intersect_sphere(c, 1.0, Ray{Vec3(0, 0, 5), Vec3(0, 0, -2)}), 2.0, 1e-12);
  // From inside: the exit; from the surface outward past tnear: nothing; a line passing at 1 + 1e-9: nothing.
  EXPECT_NEAR(intersect_sphere(c, 2.0, Ray{Vec3(0.5, 0, 0), Vec3(1, 0, 0)}), 1.5, 1e-12);
  EXPECT_TRUE(std::isinf(intersect_sphere(c, 1.0, Ray{Vec3(0, 0, 1.0002), glm::normalize(Vec3(1, 0, 1e-3)), 2e-4})));
  EXPECT_TRUE(std::isinf(intersect_sphere(c, 1.0, Ray{Vec3(-5, 1.0 + 1e-9, 0), Vec3(1, 0, 0)})));
  // Grazing at 1 - 1e-6: the two roots are 2.8e-3 apart, both found.
  const Ray graze{Vec3(-5, 1.0 - 1e-6, 0), Vec3(1, 0, 0)};
  const double half_chord = std::sqrt(1.0 - (1.0 - 1e-6) * (1.0 - 1e-6));
  EXPECT_NEAR(intersect_sphere(c, 1.0, graze), 5.0 - half_chord, 1e-12);
  EXPECT_NEAR(intersect_sphere(c, 1.0, Ray{graze.origin, graze.dir, 5.0}), 5.0 + half_chord, 1e-12);
  // Beyond tfar: nothing.
  EXPECT_TRUE(std::isinf(intersect_sphere(c, 1.0, Ray{Vec3(0, 0, 5), Vec3(0, 0, -1), 0.0, 3.9})));
  // Outside and moving away (the early exit): nothing ahead; with tnear behind the origin, the roots
  // behind it are still found.
  EXPECT_TRUE(std::isinf(intersect_sphere(c, 1.0, Ray{Vec3(0, 0, 5), Vec3(0, 0.6, 0.8)})));
  EXPECT_NEAR(intersect_sphere(c, 1.0, Ray{Vec3(0, 0, 5), Vec3(0, 0, 1), -10.0}), -6.0, 1e-12);
}

// The lanes answer each ray as intersect_sphere does: the same sphere, the same blocking and t to rounding
// (GCC fuses the AVX2 code's multiply-adds), for rays from outside, inside, on the surface leaving it
// (shadow rays, tnear > 0), grazing, bounded by tfar; both SIMD targets, and batch sizes that leave
// partial vectors.
TEST(Tracer, SpheresInLanesEqualTheClosedForm) {
  SphereSet spheres;
  const std::vector<std::pair<Vec3, double>> list = {{Vec3(0, 0, 0), 1.0}, {Vec3(1.5, 0.2, -0.3), 0.5}, {Vec3(-2, 1, 1), 0.25}};
  // Ids other than the indices, as the tracer's object indices may be.
  for (const auto& [c, r] : list)
    spheres.cx.push_back(c.x), spheres.cy.push_back(c.y), spheres.cz.push_back(c.z), spheres.radius.push_back(r),
        spheres.id.push_back(double(10 + spheres.id.size()));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto direction = [&] {
    Vec3 v;
    do v = Vec3(u(rng), u(rng), u(rng));
    while (glm::length(v) < 0.1 || glm::length(v) > 1.0);
    return glm::normalize(v);
  };
  for (const std::size_t n : {1, 3, 4, 5, 17, 400}) {
    RayBatch rays;
    std::vector<Ray> scalar;
    for (std::size_t k = 0; k < n; ++k) {
      Ray r;
      switch (k % 4) {
        case 0: r = Ray(3.0 * direction(), direction()); break;                        // from outside, anywhere
        case 1: r = Ray(0.5 * direction(), direction(), 0.0, 0.5 + 2.0 * std::abs(u(rng))); break;  // inside, bounded
        case 2: {                                                                        // leaving the unit sphere
          const Vec3 n0 = direction();
          Vec3 d = direction();
          if (glm::dot(d, n0) < 0.0) d = -d;
          r = Ray(n0 * (1.0 + 2e-4), d, 2e-4);
          break;
        }
        default: r = Ray(Vec3(-5, 1.0 - 1e-7 * std::abs(u(rng)), 0), Vec3(1, 0, 0)); break;  // grazing
      }
      scalar.push_back(r);
      rays.push(r.origin, r.dir, r.tnear, r.tfar);
    }
    for (const SimdTarget target : kSimdTargets) {
      std::vector<double> t;
      std::vector<double> which;
      std::vector<char> blocked(n, 0);
      nearest_spheres(spheres, rays, t, which, target);
      blocked_by_spheres(spheres, rays, blocked, target);
      for (std::size_t k = 0; k < n; ++k) {
        double best = std::numeric_limits<double>::infinity();
        int nearest = -1;
        bool any = false;
        Ray bounded = scalar[k];
        for (std::size_t s = 0; s < list.size(); ++s) {
          const double ts = intersect_sphere(list[s].first, list[s].second, bounded);
          if (ts < bounded.tfar) bounded.tfar = best = ts, nearest = int(s);
          any = any || std::isfinite(intersect_sphere(list[s].first, list[s].second, scalar[k]));
        }
        EXPECT_EQ(which[k], nearest >= 0 ? 10.0 + nearest : -1.0) << n << " " << k << " " << simd_target_name(target);
        if (nearest >= 0) {
          EXPECT_NEAR(t[k], best, 1e-14 * best) << n << " " << k << " " << simd_target_name(target);
        }
        EXPECT_EQ(bool(blocked[k]), any) << n << " " << k << " " << simd_target_name(target);
      }
    }
    // Rays from one point (a camera's: outside every sphere, and inside the first), as the closed form.
    for (const Vec3 origin : {Vec3(0.3, 0.4, 4.0), Vec3(0.1, -0.2, 0.3)}) {
      std::vector<double> dx, dy, dz;
      for (std::size_t k = 0; k < rays.padded_size(); ++k) {
        // Toward the spheres, or anywhere.
        const Vec3 v = k % 2 ? glm::normalize(list[k % 3].first + 0.5 * direction() - origin) : direction();
        dx.push_back(v.x), dy.push_back(v.y), dz.push_back(v.z);
      }
      for (const SimdTarget target : kSimdTargets) {
        std::vector<double> t, which;
        nearest_spheres(spheres, RaysFromPoint{origin, dx.data(), dy.data(), dz.data(), n}, t, which, target);
        for (std::size_t k = 0; k < n; ++k) {
          Ray ray(origin, Vec3(dx[k], dy[k], dz[k]));
          int nearest = -1;
          for (std::size_t s = 0; s < list.size(); ++s) {
            const double ts = intersect_sphere(list[s].first, list[s].second, ray);
            if (ts < ray.tfar) ray.tfar = ts, nearest = int(s);
          }
          EXPECT_EQ(which[k], nearest >= 0 ? 10.0 + nearest : -1.0) << n << " " << k << " " << simd_target_name(target);
          if (nearest >= 0) {
            EXPECT_NEAR(t[k], ray.tfar, 1e-14 * ray.tfar) << n << " " << k << " " << simd_target_name(target);
          }
        }
      }
    }
  }
}

TEST(Tracer, SpheresAndTrianglesTogether) {
  const SceneDesc s = parse_scene_text(R"({
    "materials": {"m": {"type": "lambert"}},
    "objects": [{"type": "sphere", "center": [0, 1, 0], "radius": 0.5, "material": "m"},
                {"type": "sphere", "center": [0, 3, 0], "radius": 0.5, "material": "m"},
                {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "size": 4, "material": "m"}]
  })", "tracer.json", ".");
  const Tracer tracer(s);
  const Ray down{Vec3(0, 5, 0), Vec3(0, -1, 0)}, beside{Vec3(1, 5, 0), Vec3(0, -1, 0)}, outside{Vec3(3, 5, 0), Vec3(0, -1, 0)};
  EXPECT_EQ(tracer.intersect(down).object, 1);  // the upper sphere first
  EXPECT_NEAR(tracer.intersect(down).t, 1.5, 1e-12);
  EXPECT_EQ(tracer.intersect(beside).object, 2);  // the plane, a triangle hit
  EXPECT_NEAR(tracer.intersect(beside).t, 5.0, 1e-5);
  EXPECT_FALSE(tracer.intersect(outside).found());
  EXPECT_TRUE(tracer.occluded(down));
  EXPECT_FALSE(tracer.occluded(Ray{Vec3(0, 5, 0), Vec3(0, -1, 0), 0.0, 1.4}));  // stops short of the sphere
  EXPECT_TRUE(tracer.occluded(beside));
  EXPECT_FALSE(tracer.occluded(Ray{Vec3(1, 5, 0), Vec3(0, -1, 0), 0.0, 4.9}));
  // The streams answer as the one-ray queries do.
  const std::vector<Ray> rays = {down, beside, outside, Ray{Vec3(0, 5, 0), Vec3(0, -1, 0), 0.0, 1.4}};
  std::vector<Hit> hits;
  std::vector<char> blocked;
  tracer.intersect(rays, hits, true);
  tracer.occluded(rays, blocked);
  for (std::size_t k = 0; k < rays.size(); ++k) {
    EXPECT_EQ(hits[k].object, tracer.intersect(rays[k]).object) << k;
    EXPECT_EQ(bool(blocked[k]), tracer.occluded(rays[k])) << k;
  }
}

// Everything that makes shadow rays: an environment (the sky's map: light and BRDF samples; or a constant
// one: BRDF samples alone), both kinds of light, a plane the spheres
// shadow, and the proposals of every kind (closed-form GGX, tabulated Beckmann, a measured table, a LUT
// whose frame follows a tangent).
class RayStreams : public ::testing::TestWithParam<const char*> {};

TEST_P(RayStreams, AndOneRayAtATimeGiveTheSameImage) {
  test::TempDir dir;
  write_gold_lut(dir.file("gold.exr"));
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

// The lanes' hits and slots (render/wavefront.h) on every SIMD target against the one-hit path's
// arithmetic: each hit placed as Frame (core/frame.h) places it, with and without a tangent, on spheres
// and triangles; each light's and the environment's slot where it lights the hit and nowhere else, with
// its direction in the frame, its ray and what arrives along it. Both with a light sample's radiance and
// density per hit (a map's) and a point light (which reads the hits' positions), and with no light sample
// (a constant environment's: no slot of its own, BRDF samples weighing 1) and a directional light alone
// (no positions). Then the slots' values against the one-hit path's formulas.
TEST(Wavefront, HitsAndSlotsEqualTheOneHitPath) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto unit = [&] { return glm::normalize(Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5) + Vec3(1e-3)); };
  const Vec3 camera(0.2, 0.5, 4.0), tangent(0.3, 1.0, 0.2);
  const double eps = 2e-4;
  for (const auto& [constant, n] : {std::pair<bool, std::size_t>{false, 1}, {false, 5}, {false, 37}, {true, 1}, {true, 5}, {true, 37}}) {
    std::vector<LaneLight> lights = {{true, 0.3, 1.0, 0.5, 3, 2, 1}};
    if (!constant) lights.push_back({false, -2.0, 3.0, 1.0, 5, 4, 3});
    TileHits tile;
    tile.resize_to(n);
    // The directions and numbers the tile reads in place, padded (finite past n).
    std::vector<double> dx(tile.padded_size(), 0.0), dy(tile.padded_size(), 0.0), dz(tile.padded_size(), 1.0);
    std::vector<double> u1(tile.padded_size(), 0.5), u2(tile.padded_size(), 0.5), u3(tile.padded_size(), 0.5);
    tile.dx = dx.data(), tile.dy = dy.data(), tile.dz = dz.data(), tile.u1 = u1.data(), tile.u2 = u2.data(), tile.u3 = u3.data();
    // Constant: the light sample's columns hold something (not to be read).
    tile.light_sampled = !constant;
    for (std::size_t k = 0; k < n; ++k) {
      const Vec3 d = glm::normalize(Vec3(u(rng) - 0.5, u(rng) - 0.5, -4.0));
      dx[k] = d.x, dy[k] = d.y, dz[k] = d.z;
      tile.t[k] = 3.0 + u(rng), tile.material[k] = double(k % 3 == 2 ? 1 : 0);
      const Vec3 g = k % 2 ? Vec3(u(rng), u(rng), -u(rng)) : unit();  // a centre, or a triangle's normal
      // A sphere through the hit: its radius the centre's distance from it.
      tile.inv_radius[k] = k % 2 ? 1.0 / glm::length(camera + tile.t[k] * d - g) : 0.0;
      tile.gx[k] = g.x, tile.gy[k] = g.y, tile.gz[k] = g.z;
      const Vec3 l = unit();
      tile.lx[k] = l.x, tile.ly[k] = l.y, tile.lz[k] = l.z, tile.light_pdf[k] = k % 5 ? 0.1 : 0.0;
      tile.light_r[k] = 0.1 * double(k % 4), tile.light_g[k] = 0.2, tile.light_b[k] = 0.1;
      u1[k] = u(rng), u2[k] = u(rng), u3[k] = u(rng);
    }
    for (const bool with_tangent : {false, true})
      for (const SimdTarget target : kSimdTargets) {
        const std::string where = std::to_string(n) + (with_tangent ? " tangent " : " ") + (constant ? "constant " : "") + simd_target_name(target);
        HitBatch hits;
        place_hits(tile, camera, eps, 0.0, with_tangent ? &tangent : nullptr, !constant, hits, target);
        ShadowBatch slots;
        SlotRanges ranges;
        if (constant) {
          EXPECT_THROW(light_slots(hits, {{false, -2.0, 3.0, 1.0, 5, 4, 3}}, eps, slots, ranges, target), std::invalid_argument);
        }
        light_slots(hits, lights, eps, slots, ranges, target);
        const auto close = [](double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(1.0, std::abs(b)); };
        // The one-hit path, hit by hit of material 0, slot by slot.
        std::size_t row = 0, env_entries = 0;
        std::vector<std::size_t> light_entries(lights.size(), 0);
        for (std::size_t k = 0; k < n; ++k) {
          if (tile.material[k] != 0.0) continue;
          ASSERT_LT(row, hits.size()) << where;
          EXPECT_EQ(hits.owner[row], double(k)) << where;
          const Vec3 dir(tile.dx[k], tile.dy[k], tile.dz[k]);
          const Vec3 p = camera + tile.t[k] * dir;
          Vec3 nrm = tile.inv_radius[k] != 0.0 ? (p - Vec3(tile.gx[k], tile.gy[k], tile.gz[k])) * tile.inv_radius[k]
                                               : glm::normalize(Vec3(tile.gx[k], tile.gy[k], tile.gz[k]));
          if (glm::dot(nrm, dir) > 0.0) nrm = -nrm;
          const Frame frame = with_tangent ? Frame(nrm, tangent) : Frame(nrm);
          const Vec3 o = frame.to_local(-dir), origin = p + eps * nrm;
          for (const auto& [a, b] : {std::pair{hits.tx[row], frame.t.x}, {hits.ty[row], frame.t.y}, {hits.tz[row], frame.t.z},
                                     {hits.bx[row], frame.b.x}, {hits.by[row], frame.b.y}, {hits.bz[row], frame.b.z},
                                     {hits.nx[row], frame.n.x}, {hits.ny[row], frame.n.y}, {hits.nz[row], frame.n.z},
                                     {hits.draws.ox[row], o.x}, {hits.draws.oy[row], o.y}, {hits.draws.oz[row], o.z},
                                     {hits.origin_x[row], origin.x}, {hits.origin_y[row], origin.y}, {hits.origin_z[row], origin.z},
                                     {hits.draws.u1[row], tile.u1[k]}, {hits.draws.u3[row], tile.u3[k]}})
            ASSERT_TRUE(close(a, b)) << where << " hit " << k << ": " << a << " against " << b;
          if (!constant) {
            EXPECT_EQ(hits.light_pdf[row], tile.light_pdf[k]) << where;
            EXPECT_EQ(hits.light_r[row], tile.light_r[k]) << where;
            EXPECT_TRUE(close(hits.px[row], p.x) && close(hits.pz[row], p.z)) << where;
          }
          // The environment's slot: where the light sample and the view are above the horizon.
          const Vec3 l(tile.lx[k], tile.ly[k], tile.lz[k]);
          const Vec3 il = frame.to_local(l);
          const double light_pdf = tile.light_pdf[k], light_r = tile.light_r[k];
          if (!constant && o.z > 0.0 && il.z > 0.0 && light_pdf > 0.0) {
            const std::size_t e = env_entries++;
            ASSERT_LT(e, ranges.lights_begin) << where;
            EXPECT_EQ(slots.owner[e], double(k)) << where;
            EXPECT_TRUE(close(slots.iz[e], il.z) && close(slots.rays.dx[e], l.x) && close(slots.rays.ox[e], origin.x)) << where;
            EXPECT_EQ(slots.light_pdf[e], light_pdf) << where;
            EXPECT_EQ(slots.arriving_r[e], light_r) << where;
            EXPECT_EQ(slots.arriving_g[e], 0.2) << where;
            EXPECT_EQ(slots.rays.tnear[e], eps) << where;
            EXPECT_TRUE(std::isinf(slots.rays.tfar[e])) << where;
          }
          for (std::size_t j = 0; j < lights.size(); ++j) {
            const LaneLight& light = lights[j];
            Vec3 d(light.x, light.y, light.z);
            double dist = std::numeric_limits<double>::infinity(), falloff = 1.0;
            if (!light.directional) {
              const Vec3 to = d - p;
              dist = glm::length(to), d = to / dist, falloff = 1.0 / (dist * dist), dist *= 1.0 - 1e-6;
            }
            const Vec3 i = frame.to_local(d);
            if (!(i.z > 0.0 && o.z > 0.0)) continue;
            const std::size_t e = ranges.light_begin[j] + light_entries[j]++;
            ASSERT_LT(e, j + 1 < lights.size() ? ranges.light_begin[j + 1] : ranges.brdf_begin) << where;
            EXPECT_EQ(slots.owner[e], double(k)) << where;
            EXPECT_TRUE(close(slots.iz[e], i.z) && close(slots.rays.dy[e], d.y) && close(slots.arriving_r[e], light.r * falloff)) << where;
            EXPECT_TRUE(light.directional ? std::isinf(slots.rays.tfar[e]) : close(slots.rays.tfar[e], dist)) << where;
          }
          ++row;
        }
        EXPECT_EQ(row, hits.size()) << where;
        EXPECT_EQ(env_entries, ranges.lights_begin) << where;
        for (std::size_t j = 0; j < lights.size(); ++j)
          EXPECT_EQ(ranges.light_begin[j] + light_entries[j], j + 1 < lights.size() ? ranges.light_begin[j + 1] : ranges.brdf_begin) << where;
        EXPECT_EQ(slots.size(), ranges.brdf_begin) << where;
        ASSERT_EQ(hits.draws.size(), hits.size()) << where;
        // The BRDF samples' slots: each direction found, from the hit, in the world by the hit's frame, and
        // nothing for the others.
        for (std::size_t r = 0; r < hits.size(); ++r) {
          const Vec3 i = glm::normalize(Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) + 0.1));
          hits.draws.ix[r] = i.x, hits.draws.iy[r] = i.y, hits.draws.iz[r] = i.z, hits.draws.found[r] = r % 3 == 1 ? 0.0 : 1.0;
        }
        brdf_slots(hits, Rgb(0.3, 0.2, 0.1), eps, slots, target);
        std::size_t e = ranges.brdf_begin;
        for (std::size_t r = 0; r < hits.size(); ++r) {
          if (r % 3 == 1) continue;
          ASSERT_LT(e, slots.size()) << where;
          const Vec3 i = hits.draws.i(r), t(hits.tx[r], hits.ty[r], hits.tz[r]), b(hits.bx[r], hits.by[r], hits.bz[r]);
          const Vec3 world = i.x * t + i.y * b + i.z * Vec3(hits.nx[r], hits.ny[r], hits.nz[r]);
          EXPECT_EQ(slots.owner[e], hits.owner[r]) << where;
          EXPECT_TRUE(close(slots.iz[e], i.z) && close(slots.oz[e], hits.draws.oz[r]) && close(slots.rays.dx[e], world.x) &&
                      close(slots.rays.dz[e], world.z) && close(slots.rays.oy[e], hits.origin_y[r]))
              << where << " row " << r;
          EXPECT_EQ(slots.arriving_b[e], 0.1) << where;
          EXPECT_EQ(slots.light_pdf[e], 0.0) << where;
          EXPECT_TRUE(std::isinf(slots.rays.tfar[e])) << where;
          ++e;
        }
        EXPECT_EQ(e, slots.size()) << where;
        // The values (the one-hit path's, render/integrator.cpp): an environment light sample f L cos w / p_light,
        // a light's f E cos, a BRDF sample f cos / p L w, w by the power heuristic, 1 against a density of 0
        // (a constant environment's, or a map's where it is black); none cast for a BRDF sample of density 0.
        // Densities so small that their squares underflow (1e-170) too, against 0 and against another.
        for (std::size_t q = 0; q < slots.size(); ++q) {
          slots.r[q] = 0.5 + 0.01 * double(q % 7), slots.g[q] = 0.2, slots.b[q] = 0.1;
          slots.pdf[q] = q % 6 == 5 ? 0.0 : q % 6 == 4 ? 1e-170 : 0.3 + 0.1 * double(q % 5);
          if (q >= ranges.brdf_begin && !constant) slots.light_pdf[q] = q % 4 == 0 ? 0.0 : q % 4 == 1 ? 3e-170 : 0.2;  // a map looked up
        }
        shadow_values(slots, ranges, target);
        for (std::size_t q = 0; q < slots.size(); ++q) {
          const double f = slots.r[q], arriving = slots.arriving_r[q], cos_i = slots.iz[q], pdf = slots.pdf[q], light_pdf = slots.light_pdf[q];
          double want = f * arriving * cos_i;  // a light
          // w(p, q) / p = p / (p^2 + q^2) in long double, whose exponent holds the squares of 1e-170.
          const auto weight_over = [](long double own, long double other) { return double(own / (own * own + other * other)); };
          if (q < ranges.lights_begin) want = f * arriving * cos_i * weight_over(light_pdf, pdf);
          if (q >= ranges.brdf_begin) {
            EXPECT_EQ(slots.casts[q], pdf > 0.0 ? 1.0 : 0.0) << where << " entry " << q;
            if (!(pdf > 0.0)) continue;
            want = f * cos_i * arriving * weight_over(pdf, light_pdf);
            if (light_pdf == 0.0) {
              EXPECT_TRUE(close(want, f * cos_i / pdf * arriving)) << where;  // weighs 1
            }
          }
          ASSERT_TRUE(std::isfinite(slots.value_r[q])) << where << " entry " << q;
          EXPECT_TRUE(close(slots.value_r[q], want)) << where << " entry " << q << ": " << slots.value_r[q] << " against " << want;
        }
      }
  }
}

TEST(Wavefront, TakeHitsLooksUpEachPixelsObject) {
  // Objects: a sphere shaded in lanes, a mesh shaded in lanes, a sphere shaded one hit at a time. Runs of
  // one object (the one-lookup vectors), mixed vectors and misses; every target; every entry exactly.
  LaneObjects objects;
  objects.material = {0.0, 1.0, -1.0};
  objects.cx = {0.5, 0.0, -2.0}, objects.cy = {1.0, 0.0, 3.0}, objects.cz = {-1.0, 0.0, 0.25};
  objects.inv_radius = {2.0, 0.0, 0.125};
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Rgb background(0.3, 0.2, 0.1);
  for (const std::size_t n : {1u, 5u, 16u, 37u, 256u})
    for (const SimdTarget target : kSimdTargets) {
      RayHits hits;
      hits.resize_to(n);
      for (std::size_t k = 0; k < hits.padded_size(); ++k) {
        const int run = int(k / 8) % 5;  // 8 alike (objects 0, 1, 2, a miss), then mixed
        hits.object[k] = run == 4 ? double(int(u(rng) * 4.0) - 1) : run == 3 ? -1.0 : double(run);
        hits.t[k] = hits.object[k] >= 0.0 ? 1.0 + u(rng) : std::numeric_limits<double>::infinity();
        hits.ngx[k] = hits.object[k] == 1.0 ? u(rng) : 0.0, hits.ngy[k] = hits.object[k] == 1.0 ? 1.0 : 0.0, hits.ngz[k] = hits.object[k] == 1.0 ? -0.5 : 0.0;
      }
      TileHits tile;
      tile.resize_to(n);
      std::vector<double> alpha(hits.padded_size()), radiance[3];
      for (auto& c : radiance) c.assign(hits.padded_size(), -7.0);
      double* out[3] = {radiance[0].data(), radiance[1].data(), radiance[2].data()};
      take_hits(hits, objects, background, tile, alpha.data(), out, target);
      const std::string where = std::to_string(n) + " " + simd_target_name(target);
      for (std::size_t k = 0; k < hits.padded_size(); ++k) {
        const double o = hits.object[k];
        const bool hit = o >= 0.0;
        const std::size_t i = hit ? std::size_t(o) : 0;
        EXPECT_EQ(tile.material[k], hit ? objects.material[i] : -1.0) << where << " " << k;
        EXPECT_EQ(alpha[k], hit ? 1.0 : 0.0) << where << " " << k;
        for (int c = 0; c < 3; ++c) EXPECT_EQ(radiance[c][k], hit ? 0.0 : background[c]) << where << " " << k << " channel " << c;
        if (!hit) continue;
        EXPECT_EQ(tile.t[k], hits.t[k]) << where << " " << k;
        EXPECT_EQ(tile.inv_radius[k], objects.inv_radius[i]) << where << " " << k;
        EXPECT_EQ(tile.gx[k], i == 1 ? hits.ngx[k] : objects.cx[i]) << where << " " << k;
        EXPECT_EQ(tile.gy[k], i == 1 ? hits.ngy[k] : objects.cy[i]) << where << " " << k;
        EXPECT_EQ(tile.gz[k], i == 1 ? hits.ngz[k] : objects.cz[i]) << where << " " << k;
      }
    }
}

TEST(Wavefront, SamplesAddToTheSumsAsOneAtATime) {
  // Lengths around the lane counts, radiance with a NaN or an infinity in one channel (the pixel adds
  // nothing but its alpha), every target; the sums exactly.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const std::size_t n : {1u, 3u, 4u, 7u, 8u, 9u, 17u, 256u})
    for (const SimdTarget target : kSimdTargets) {
      std::vector<double> radiance[3], alpha(n), sum[4], want[4];
      for (auto& c : radiance) c.resize(n);
      for (int c = 0; c < 4; ++c) sum[c].resize(n);
      for (std::size_t k = 0; k < n; ++k) {
        for (auto& c : radiance) c[k] = u(rng);
        if (k % 5 == 1) radiance[k % 3][k] = k % 2 ? std::numeric_limits<double>::quiet_NaN() : std::numeric_limits<double>::infinity();
        alpha[k] = double(k % 2);
        for (int c = 0; c < 4; ++c) sum[c][k] = u(rng);
      }
      for (int c = 0; c < 4; ++c) want[c] = sum[c];
      for (std::size_t k = 0; k < n; ++k) {
        const bool finite = std::isfinite(radiance[0][k]) && std::isfinite(radiance[1][k]) && std::isfinite(radiance[2][k]);
        for (int c = 0; c < 3; ++c) want[c][k] += finite ? radiance[c][k] : 0.0;
        want[3][k] += alpha[k];
      }
      const double* in[3] = {radiance[0].data(), radiance[1].data(), radiance[2].data()};
      double* out[4] = {sum[0].data(), sum[1].data(), sum[2].data(), sum[3].data()};
      add_samples(in, alpha.data(), out, n, target);
      for (int c = 0; c < 4; ++c) EXPECT_EQ(sum[c], want[c]) << n << " " << simd_target_name(target) << " channel " << c;
    }
}

TEST(Camera, SamplesInSimdLanesEqualOneAtATime) {
  // The numbers exactly (integer arithmetic, and 32 bits to a double), the directions to rounding; pixels
  // of a wide image (large keys), seeds that set the high bits, sample indices past 2^24 (shifted by 40),
  // batches of every length modulo the lane count; every target (the best one: AVX-512's whole 64-bit
  // multiplications where the CPU has it; AVX2's from 32-bit halves; the baseline).
  PinholeCamera camera;
  camera.position = Vec3(0.0, 0.6, 4.0);
  camera.forward = glm::normalize(-camera.position);
  camera.right = glm::normalize(glm::cross(camera.forward, Vec3(0.0, 1.0, 0.0)));
  camera.up = glm::cross(camera.right, camera.forward);
  camera.tan_half = std::tan(0.5 * 30.0 * kPi / 180.0), camera.aspect = 16000.0 / 9000.0;
  camera.to_sx = 2.0 / 16000.0, camera.to_sy = 2.0 / 9000.0;
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> px(0, 15999), py(0, 8999);
  for (const SimdTarget target : kSimdTargets)
    for (std::size_t n : {1, 3, 4, 15, 16, 17, 61})
      for (const auto& [seed, s] : {std::pair<std::uint64_t, int>{1, 0}, {0xFFFFFFFFFFFFull, 63}, {7, (1 << 24) + 5}}) {
        CameraSampleBatch batch;
        std::vector<std::pair<int, int>> pixels;
        for (std::size_t k = 0; k < n; ++k) {
          pixels.emplace_back(k == 0 ? 0 : px(rng), k == 0 ? 0 : py(rng));
          batch.push(pixels.back().first, pixels.back().second);
        }
        camera_sample_batch(camera, seed, s, batch, target);
        // Only the numbers a constant environment reads (the camera's and the BRDF sample's), into a batch
        // whose columns hold something else: those, the same; the rest, not written.
        CameraSampleBatch some = batch;
        for (auto& column : some.u) std::fill(column.begin(), column.end(), -1.0);
        const unsigned read = sample_numbers_read(true, false);
        camera_sample_batch(camera, seed, s, some, target, read);
        for (std::size_t k = 0; k < n; ++k) {
          const auto [x, y] = pixels[k];
          const std::uint64_t start = SampleSequence::start(seed, SampleSequence::pixel_key(x, y), s);
          double u[kSampleNumbers];
          for (int j = 0; j < kSampleNumbers; ++j) {
            u[j] = SampleSequence::number(start, j);
            ASSERT_EQ(batch.u[j][k], u[j]) << "number " << j << " of pixel (" << x << ", " << y << ")";
            ASSERT_EQ(some.u[j][k], read >> j & 1u ? u[j] : -1.0) << "number " << j << " of pixel (" << x << ", " << y << ")";
            ASSERT_TRUE(u[j] >= 0.0 && u[j] < 1.0);
          }
          const Vec3 want = camera.direction(x, y, u[0], u[1]), got = batch.d(k);
          EXPECT_NEAR(got.x, want.x, 1e-15) << k;
          EXPECT_NEAR(got.y, want.y, 1e-15) << k;
          EXPECT_NEAR(got.z, want.z, 1e-15) << k;
        }
      }
}

// Every material type of the registry (render/scene.h) in its plain form runs on the stream path as it
// declares: sampling and density in SIMD lanes, and f too where it says `all`. A type whose models leave the
// lanes (a new model without kernels, a proposal they do not hold) fails here instead of rendering one
// pair at a time unseen. The loop reads the registry, so a new type is tested as soon as it is listed.
// A render's EXR says in which colour space its pixels are: OpenEXR's chromaticities (Rec.709 primaries,
// D65 white), which compositors read, and the name OpenImageIO reads.
TEST(Render, ExrCarriesItsChromaticities) {
  test::TempDir dir;
  RenderedImage image;
  image.width = image.height = 2;
  image.rgba.assign(16, 0.5f);
  write_exr(dir.file("x.exr"), image, {{"source", "test"}});
  const auto in = OIIO::ImageInput::open(dir.file("x.exr"));
  ASSERT_TRUE(in);
  const OIIO::ImageSpec& spec = in->spec();
  const OIIO::ParamValue* c = spec.find_attribute("chromaticities", OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, 8));
  ASSERT_NE(c, nullptr);
  const float rec709[8] = {0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};
  for (int k = 0; k < 8; ++k) EXPECT_NEAR(static_cast<const float*>(c->data())[k], rec709[k], 1e-6) << k;
  EXPECT_EQ(spec.get_string_attribute("oiio:ColorSpace"), "lin_rec709");
  EXPECT_EQ(spec.get_string_attribute("facetfit:source"), "test");
}

TEST(Shading, EveryMaterialTypeRunsInTheLanesItDeclares) {
  test::TempDir dir;
  const std::string lut = dir.file("gold.exr");
  write_gold_lut(lut);
  const SceneDesc scene;
  for (const MaterialType& type : kMaterialTypes) {
    MaterialDesc m;
    m.type = type.name;
    m.file = type.reads_lut ? lut : type.needs_file ? "builtin:gold-ggx-0.15" : "";
    const std::shared_ptr<const ShadingModel> model = load_material(scene, m);
    EXPECT_TRUE(model->has_lanes()) << type.name;
    if (type.lanes == MaterialType::Lanes::all) {
      EXPECT_TRUE(model->f_in_lanes()) << type.name;
    }
  }
  // Controls: a stretched LUT draws from its own visible normals, one pair at a time; an RGL file's f is
  // evaluated one pair at a time under its lanes' proposal.
  MaterialDesc stretched;
  stretched.type = "lut", stretched.file = lut, stretched.stretch = Stretch(2.0, 0.5, 0.0);
  EXPECT_FALSE(load_material(scene, stretched)->has_lanes());
  MaterialDesc ggx_of_lut;
  ggx_of_lut.type = "ggx", ggx_of_lut.file = lut;
  EXPECT_FALSE(load_material(scene, ggx_of_lut)->f_in_lanes());
}

// A render in another working space converts every colour a material has: the scene's (lambert, plain
// GGX), a measurement's and each colour of a LUT (Fresnel curve, body, each fit's f0 and f82, the
// closures' lobes). With a permutation of the channels for the space, every material type's f must be
// the Rec.709 f permuted, pair by pair: a colour left out shows as an unpermuted channel. A LUT of a body
// under a coat, with closures.
TEST(WorkingSpace, EveryMaterialTypeConvertsEveryColour) {
  test::TempDir dir;
  const std::string lut = dir.file("paint.exr");
  const Fitter fitter{FitOptions{}};
  write_lut(lut, make_lut(fitter.fit(load_table("builtin:blue-clearcoat-paint")), fitter.quadrature(), "builtin:blue-clearcoat-paint",
                          "x", 0.02, true));
  ASSERT_FALSE(read_lut(lut).meta.closures.empty());
  SceneDesc rec709, permuted;
  permuted.working_space = "gbr";
  permuted.from_rec709 = ColorMatrix(Vec3(0, 0, 1), Vec3(1, 0, 0), Vec3(0, 1, 0));  // (r, g, b) -> (g, b, r)
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const MaterialType& type : kMaterialTypes) {
    for (const std::string fresnel : {"f82", "curve"}) {
      MaterialDesc m;
      m.type = type.name;
      m.file = type.reads_lut ? lut : type.needs_file ? "builtin:blue-clearcoat-paint" : "";
      m.f0 = Rgb(0.9, 0.5, 0.2), m.albedo = Rgb(0.7, 0.3, 0.1), m.fresnel = fresnel;
      const auto a = load_material(rec709, m), b = load_material(permuted, m);
      for (int k = 0; k < 50; ++k) {
        const Vec3 o = spherical_direction(1.4 * u(rng), 6.28 * u(rng)), i = spherical_direction(1.4 * u(rng), 6.28 * u(rng));
        const std::optional<Rgb> fa = a->brdf().eval(o, i), fb = b->brdf().eval(o, i);
        ASSERT_EQ(fa.has_value(), fb.has_value()) << type.name;
        if (!fa) continue;
        const Rgb want = permuted.from_rec709 * *fa;
        for (int c = 0; c < 3; ++c) ASSERT_NEAR((*fb)[c], want[c], 1e-6 * (1.0 + want[c])) << type.name << " " << fresnel << " channel " << c;
      }
    }
  }
}

TEST(Shading, GgxInSimdLanesEqualsOnePairAtATime) {
  // Every term the GGX kernels hold (render/ggx_batch.h): the three Smith forms, F82-tint and the Fresnel
  // curve, a body and a coat, from alpha 0.005 to 1.5, over pairs that include grazing and below-horizon
  // directions and batches of every length modulo the lane count; both the AVX2 code (where the CPU has
  // it) and the baseline, against ShadingModel's one pair at a time.
  const FresnelCurve curve = coloured_curve();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto direction = [&] { return lane_test_direction(rng, 0.05, true); };
  // A drawn direction within 1e-9: the visible normals' sqrt(1 - p1^2) (model/ggx_visible.h) turns the
  // last bit of p1 or p1^2 (the lanes fuse multiply-adds, take their own series' cosine and, on AVX-512, u1 times
  // the part's reciprocal) into 1e-16 / sqrt(1 - p1^2) of i, and p1 comes within 1e-9 of 1 (u1 rescaled
  // near the end of the lobe's part). With the lanes' divisions as they were, one sample of this test's
  // numbers was 1.1e-12 off too.
  const auto near = [](double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(1.0, std::abs(b)); };
  int cases = 0, found = 0, refused = 0;
  for (const double alpha : {0.005, 0.3, 1.5})
    for (const Smith smith : {Smith::masking, Smith::correlated, Smith::separable})
      for (int variant = 0; variant < 4; ++variant)
        for (const SimdTarget target : kSimdTargets) {
          const bool with_curve = variant & 1, layered = variant & 2;
          const Rgb f0(0.9, 0.6, 0.3), body = layered ? Rgb(0.3, 0.2, 0.1) : Rgb(0.0);
          const Coat coat = layered ? Coat{0.05, 0.04} : Coat{};
          const Ndf ndf = Ndf::isotropic(NdfType::ggx, alpha);
          const auto brdf = with_curve ? std::make_shared<ParametricBrdf>(ndf, smith, curve, body, coat)
                                       : std::make_shared<ParametricBrdf>(ndf, smith, f0, Rgb(0.8, 0.7, 0.5), body, coat);
          const ShadingModel model(brdf, std::make_shared<GgxProposal>(alpha, f0, body, coat));
          ASSERT_TRUE(model.lanes<GgxLanes>());
          const std::string where = "alpha " + std::to_string(alpha) + " variant " + std::to_string(variant) + " " + simd_target_name(target);
          EvaluationBatch lanes, reference;
          SampleBatch drawn, one_by_one;
          const std::size_t n = 200 + std::size_t(cases % 17);
          for (std::size_t k = 0; k < n; ++k) {
            const Vec3 o = direction(), i = direction();
            lanes.push(o, i), reference.push(o, i);
            const double u1 = u(rng), u2 = u(rng), u3 = u(rng);
            drawn.push(o, u1, u2, u3), one_by_one.push(o, u1, u2, u3);
          }
          eval_ggx_batch(model.lanes<GgxLanes>()->model, lanes, target), model.eval(reference, false);
          sample_ggx_batch(model.lanes<GgxLanes>()->model, drawn, target), model.sample_directions(one_by_one, false);
          for (std::size_t k = 0; k < n; ++k) {
            const double values[4][2] = {{lanes.r[k], reference.r[k]}, {lanes.g[k], reference.g[k]}, {lanes.b[k], reference.b[k]},
                                         {lanes.pdf[k], reference.pdf[k]}};
            for (const auto& v : values) {
              ASSERT_TRUE(std::isfinite(v[0])) << where << " pair " << k << " o.z " << lanes.oz[k] << " i.z " << lanes.iz[k] << " against " << v[1];
              ASSERT_TRUE(near(v[0], v[1])) << where << " pair " << k << ": " << v[0] << " against " << v[1];
            }
            ASSERT_EQ(drawn.found[k], one_by_one.found[k]) << where << " sample " << k;
            if (!one_by_one.found[k]) {
              ++refused;
              continue;
            }
            ++found;
            for (const auto& [a, b] : {std::pair{drawn.ix[k], one_by_one.ix[k]}, {drawn.iy[k], one_by_one.iy[k]}, {drawn.iz[k], one_by_one.iz[k]}})
              ASSERT_LE(std::abs(a - b), 1e-9) << where << " sample " << k << " o.z " << drawn.oz[k] << ": " << a << " against " << b;
          }
          ++cases;
        }
  EXPECT_EQ(cases, 108);  // every case on each of the three SIMD targets
  // Both outcomes were compared (about half the views are below the horizon).
  EXPECT_GT(found, 5000);
  EXPECT_GT(refused, 1000);
}

// A Lambertian surface in lanes (render/lambert_batch.h) on every SIMD target, against ShadingModel's
// one pair at a time: f, density and cosine sampling, views and lights on both sides of the horizon.
TEST(Shading, LambertInSimdLanesEqualsOnePairAtATime) {
  const Rgb albedo(0.5, 0.3, 0.1);
  const ShadingModel model(std::make_shared<LambertBrdf>(albedo), nullptr);
  ASSERT_TRUE(model.has_lanes());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto direction = [&] {
    const double z = 2.0 * u(rng) - 1.0, phi = 2.0 * kPi * u(rng), r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return Vec3(r * std::cos(phi), r * std::sin(phi), z);
  };
  EvaluationBatch pairs;
  SampleBatch draws;
  for (int k = 0; k < 203; ++k) {
    const Vec3 o = direction();
    pairs.push(o, direction());
    draws.push(o, u(rng), u(rng), u(rng));
  }
  EvaluationBatch reference = pairs;
  model.eval(reference, false);
  SampleBatch one_by_one = draws;
  model.sample_directions(one_by_one, false);
  int found = 0, lit = 0;
  for (const SimdTarget target : kSimdTargets) {
    EvaluationBatch lanes = pairs;
    eval_lambert_batch(albedo, lanes, target);
    SampleBatch drawn = draws;
    sample_lambert_batch(drawn, target);
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      EXPECT_EQ(lanes.r[k], reference.r[k]) << simd_target_name(target) << " pair " << k;
      EXPECT_EQ(lanes.b[k], reference.b[k]) << simd_target_name(target) << " pair " << k;
      EXPECT_EQ(lanes.pdf[k], reference.pdf[k]) << simd_target_name(target) << " pair " << k;
      lit += reference.r[k] > 0.0;
      ASSERT_EQ(drawn.found[k], one_by_one.found[k]) << simd_target_name(target) << " sample " << k;
      if (!one_by_one.found[k]) continue;
      ++found;
      for (const auto& [a, b] : {std::pair{drawn.ix[k], one_by_one.ix[k]}, {drawn.iy[k], one_by_one.iy[k]}, {drawn.iz[k], one_by_one.iz[k]}})
        EXPECT_NEAR(a, b, 1e-12) << simd_target_name(target) << " sample " << k;
    }
  }
  // Both sides of the horizon were compared.
  EXPECT_GT(found, 3 * 60);
  EXPECT_LT(found, 3 * 150);
  EXPECT_GT(lit, 3 * 25);
}

TEST(Shading, TabulatedInSimdLanesEqualsOnePairAtATime) {
  // Every term the tabulated kernel holds (render/tabulated_batch.h): D's spline from a peak a node wide to
  // a flat lobe (GGX 0.005 to 1.5 and Beckmann tabulated), G1's table under the three Smith forms, the
  // Fresnel curve, a body (Minnaert's) and a coat, the visible slopes' density at every view slice and their
  // draw (the slice, the cells' bisections from the guides, the slopes' frame); pairs that include grazing
  // and below-horizon directions, batches of every length modulo the lane count, every SIMD target the CPU
  // has, against ShadingModel's one pair at a time.
  // The lanes compute in single precision: both paths take the same inputs, rounded to single (the
  // directions and numbers as the lanes see them; a direction within 1e-160 of the normal is the normal,
  // a cos(theta) of 1e-170 is the horizon).
  const FresnelCurve curve = coloured_curve();
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto direction = [&] { return lane_test_direction(rng, 0.05, true); };
  // f and the density relative to the value (or to 1e-3 of the batch's largest) within 2e-4 (worst seen
  // 4.9e-5): single precision's 6e-8, through the spline's, the tables' and the Fresnel curve's lookups
  // (theta_h from 1 - h.z = sin^2 / (1 + h.z), not from h.z: render/lanes-inl.h, acos).
  // A drawn direction within 1e-3 (most within 1e-5; worst seen 2.2e-4 for alpha 0.005, where the cells'
  // slopes x = c v / (1 - |v|) stretch v's rounding), except where a number falls within rounding of a
  // boundary between view slices or cells, which the two paths may then put on either side: at most 1 in
  // 1,000 draws (seen: 1 in 21,600). A direction found by one path and not the other only on the horizon.
  int cases = 0, compared = 0, found = 0, flips = 0;
  double worst = 0.0, sample_worst = 0.0;
  for (const auto& [type, alpha] : {std::pair{NdfType::ggx, 0.005}, {NdfType::ggx, 0.3}, {NdfType::ggx, 1.5}, {NdfType::beckmann, 0.3}})
    for (const Smith smith : {Smith::masking, Smith::correlated, Smith::separable})
      for (const bool layered : {false, true})
        for (const SimdTarget target : kSimdTargets) {
          MicrofacetTables tables{tabulate_ndf(Ndf::isotropic(type, alpha)), smith, curve, layered ? Rgb(0.3, 0.2, 0.1) : Rgb(0.0),
                                  layered ? Coat{0.05, 0.04} : Coat{}, layered ? 1.4 : 1.0};  // 1.4: Minnaert's body
          const auto lobe = std::make_shared<TabulatedMicrofacet>(tables);
          const ShadingModel model(lobe, VisibleSlopeProposal::of(*lobe));
          ASSERT_TRUE(model.lanes<TabulatedLanes>());
          ASSERT_TRUE(model.lanes<TabulatedLanes>()->model.f);
          ASSERT_TRUE(model.has_lanes());
          const std::string where = "alpha " + std::to_string(alpha) + (layered ? " layered" : "") + " " + simd_target_name(target);
          EvaluationBatch lanes, reference;
          SampleBatch drawn, one_by_one;
          const std::size_t n = 300 + std::size_t(cases % 17);
          for (std::size_t k = 0; k < n; ++k) {
            Vec3 o = direction(), i = direction();
            if (k % 3 == 0) i = glm::normalize(Vec3(-o.x, -o.y, o.z) + 0.02 * direction());  // near the peak
            o = single(o), i = single(i);
            lanes.push(o, i), reference.push(o, i);
            const double u1 = single(u(rng)), u2 = single(u(rng)), u3 = single(u(rng));
            drawn.push(o, u1, u2, u3), one_by_one.push(o, u1, u2, u3);
          }
          eval_tabulated_batch(model.lanes<TabulatedLanes>()->model, lanes, target), model.eval(reference, false);
          sample_tabulated_batch(model.lanes<TabulatedLanes>()->model, drawn, target), model.sample_directions(one_by_one, false);
          // Pairs that ask for f alone (a light's): the same f, and no density.
          EvaluationBatch f_only;
          for (std::size_t k = 0; k < n; ++k) f_only.push(lanes.o(k), lanes.i(k), false);
          eval_tabulated_batch(model.lanes<TabulatedLanes>()->model, f_only, target);
          for (std::size_t k = 0; k < n; ++k) {
            ASSERT_EQ(f_only.pdf[k], 0.0) << where << " pair " << k;
            ASSERT_EQ(f_only.r[k], lanes.r[k]) << where << " pair " << k;
            ASSERT_EQ(f_only.b[k], lanes.b[k]) << where << " pair " << k;
          }
          for (std::size_t k = 0; k < n; ++k) {
            if (drawn.found[k] != one_by_one.found[k]) {
              const double z = drawn.found[k] ? drawn.iz[k] : one_by_one.iz[k];
              ASSERT_LT(std::abs(z), 1e-5) << where << " sample " << k << ": found by one path only, i.z " << z;
              ++flips;
              continue;
            }
            if (!one_by_one.found[k]) continue;
            ++found;
            const Vec3 a = drawn.i(k), b = one_by_one.i(k);
            if (glm::length(a - b) > 1e-3) {
              ++flips;
              continue;
            }
            sample_worst = std::max(sample_worst, glm::length(a - b));
          }
          double largest[4] = {};
          for (std::size_t k = 0; k < n; ++k)
            for (const auto& [c, v] : {std::pair{0, reference.r[k]}, {1, reference.g[k]}, {2, reference.b[k]}, {3, reference.pdf[k]}})
              largest[c] = std::max(largest[c], std::abs(v));
          for (std::size_t k = 0; k < n; ++k) {
            const double values[4][2] = {{lanes.r[k], reference.r[k]}, {lanes.g[k], reference.g[k]}, {lanes.b[k], reference.b[k]},
                                         {lanes.pdf[k], reference.pdf[k]}};
            for (int c = 0; c < 4; ++c) {
              const double a = values[c][0], b = values[c][1];
              ASSERT_TRUE(std::isfinite(a)) << where << " pair " << k << " value " << c << " o.z " << lanes.oz[k] << " i.z " << lanes.iz[k] << " against " << b;
              const double scale = std::max(std::abs(b), 1e-3 * largest[c]);
              ASSERT_LE(std::abs(a - b), 2e-4 * scale) << where << " pair " << k << " value " << c << ": " << a << " against " << b;
              if (scale > 0.0) worst = std::max(worst, std::abs(a - b) / scale);
              compared += b != 0.0;
            }
          }
          ++cases;
        }
  std::printf("[ lanes ] worst relative difference of f and pdf %.2e, of a drawn direction %.2e; %d draws on either side of a boundary\n",
              worst, sample_worst, flips);
  EXPECT_EQ(cases, 72);  // every case on each of the three SIMD targets
  EXPECT_GT(compared, 20000);  // about half the pairs are above the horizon, four values each
  EXPECT_LE(flips, found / 1000);
  EXPECT_GT(found, 5000);
}

TEST(Shading, TabulatedProposalInSimdLanesEqualsOnePairAtATime) {
  // A tabulated lobe's visible slopes that only sample another BRDF (a Beckmann lobe's tabulated NDF, a
  // measured table's fitted LUT): the lanes draw the directions and give the density, f stays the BRDF's
  // own. ShadingModel's batch calls in lanes against the same calls one pair at a time.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto direction = [&] { return lane_test_direction(rng, 0.0); };
  int found = 0;
  for (const bool layered : {false, true}) {
    const Ndf ndf = Ndf::isotropic(NdfType::beckmann, 0.25);
    const Rgb body = layered ? Rgb(0.2, 0.3, 0.4) : Rgb(0.0);
    const Coat coat = layered ? Coat{0.05, 0.04} : Coat{};
    const auto brdf = std::make_shared<ParametricBrdf>(ndf, Smith::correlated, Rgb(0.9, 0.6, 0.3), Rgb(0.8, 0.7, 0.5), body, coat);
    const auto proposal = std::make_shared<VisibleSlopeProposal>(tabulate_ndf(ndf), ProposalParts(Rgb(1.0), body, coat));
    const ShadingModel model(brdf, proposal);
    ASSERT_TRUE(model.has_lanes());
    ASSERT_FALSE(model.lanes<TabulatedLanes>()->model.f);
    EvaluationBatch lanes, reference;
    SampleBatch drawn, one_by_one;
    for (std::size_t k = 0; k < 403; ++k) {
      // In single precision, as the lanes see them (Shading.TabulatedInSimdLanesEqualsOnePairAtATime).
      const Vec3 o = single(direction()), i = single(direction());
      lanes.push(o, i), reference.push(o, i);
      const double u1 = single(u(rng)), u2 = single(u(rng)), u3 = single(u(rng));
      drawn.push(o, u1, u2, u3), one_by_one.push(o, u1, u2, u3);
    }
    model.eval(lanes, true), model.eval(reference, false);
    model.sample_directions(drawn, true), model.sample_directions(one_by_one, false);
    for (std::size_t k = 0; k < lanes.size(); ++k) {
      // f is the BRDF's, one pair at a time either way; the density and the draw to single precision's
      // rounding, as in that test (no draw here fell on a boundary).
      EXPECT_EQ(lanes.f(k), reference.f(k)) << k;
      EXPECT_NEAR(lanes.pdf[k], reference.pdf[k], 2e-4 * std::max(1.0, reference.pdf[k])) << k;
      ASSERT_EQ(drawn.found[k], one_by_one.found[k]) << k;
      if (!one_by_one.found[k]) continue;
      ++found;
      EXPECT_LE(glm::length(drawn.i(k) - one_by_one.i(k)), 1e-3) << k;
    }
  }
  EXPECT_GT(found, 300);
}

TEST(Shading, HalfDiffTableInSimdLanesEqualsOnePairAtATime) {
  // A MERL-layout table's linear lookup (render/merl_batch.h) against HalfDiffTable::eval: a glossy table with
  // bins made missing (every neighbour of some pairs, one channel of others) and negative values, pairs
  // near the normal, near the mirror direction, grazing and below the horizon; both targets.
  HalfDiffTable table = load_table("builtin:red-plastic");
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int q = 0; q < 200000; ++q) {
    const int i = int(u(rng) * 90), j = int(u(rng) * 90), k = int(u(rng) * 180);
    if (q % 2) table.set_missing(i, j, k);
    else table.channel(q % 3)[HalfDiffTable::index(i, j, k)] = q % 4 ? -0.01f : std::numeric_limits<float>::quiet_NaN();
  }
  const auto model = MerlBatchModel::of(table);
  ASSERT_TRUE(model);
  const auto direction = [&] { return lane_test_direction(rng, 0.05, true); };
  double worst = 0.0;
  int values = 0, zero = 0;
  for (const SimdTarget target : kSimdTargets) {
    EvaluationBatch lanes;
    std::vector<Vec3> os, is;
    for (std::size_t k = 0; k < 4003; ++k) {
      Vec3 o = direction(), i = direction();
      if (k % 4 == 0) i = glm::normalize(Vec3(-o.x, -o.y, o.z) + 0.01 * direction());  // near the mirror direction
      if (k % 4 == 1) o = glm::normalize(Vec3(0.001 * o.x, 0.001 * o.y, 1.0)), i = glm::normalize(Vec3(-o.x, o.y, o.z));  // near the normal
      lanes.push(o, i), os.push_back(o), is.push_back(i);
    }
    eval_merl_batch(*model, lanes, target);
    for (std::size_t k = 0; k < os.size(); ++k) {
      const Rgb expected = table.eval(os[k], is[k]).value_or(Rgb(0.0));
      for (int c = 0; c < 3; ++c) {
        const double a = c == 0 ? lanes.r[k] : (c == 1 ? lanes.g[k] : lanes.b[k]), b = expected[c];
        ASSERT_TRUE(std::isfinite(a)) << k;
        // To rounding, through the arc cosines' and arc tangent's last bits (worst 3.5e-11).
        ASSERT_LE(std::abs(a - b), 1e-9 * std::max(std::abs(b), 1e-3)) << simd_target_name(target) << " " << "pair " << k << " channel " << c
                                                                        << ": " << a << " against " << b;
        worst = std::max(worst, std::abs(a - b) / std::max(std::abs(b), 1e-3));
        ++values, zero += b == 0.0;
      }
    }
  }
  std::printf("[ lanes ] worst relative difference %.2e over %d values, %d of them zero\n", worst, values, zero);
  EXPECT_GT(values - zero, 10000);
  EXPECT_GT(zero, 1000);  // below the horizon, or a channel without a measured neighbour
}

// A scene of 100k materials (2.7 MB) is read whole: the depth-limiting callback parser took minutes on it
// (issue 47; BM_ParseScene times it). Brackets inside names are not nesting, and a string's escaped quote
// does not end it.
TEST(Render, LargeScenesParseWhole) {
  constexpr int kMaterials = 100000;
  std::string text = R"({"materials": {)";
  for (int k = 0; k < kMaterials; ++k) text += "\"m" + std::to_string(k) + "\": {\"type\": \"lambert\"}, ";
  text += std::string(R"("[[[[\"{{{{": {"type": "lambert"}}, "objects": [{"type": "sphere", "material": "[[[[\"{{{{"}]})");
  const SceneDesc s = parse_scene_text(text, "large.json", ".");
  EXPECT_EQ(s.materials.size(), std::size_t(kMaterials) + 1);
  EXPECT_EQ(s.materials.count("[[[[\"{{{{"), 1u);
  // 33 levels is refused, 32 is not a nesting error.
  const auto nested = [](int levels) { return std::string(std::size_t(levels), '[') + std::string(std::size_t(levels), ']'); };
  EXPECT_NE(test::error_of([&] { parse_scene_text(nested(33), "deep.json", "."); }).find("deep.json: nested more than 32 levels deep"),
            std::string::npos);
  EXPECT_NE(test::error_of([&] { parse_scene_text(nested(32), "deep.json", "."); }).find("deep.json: not a JSON object"), std::string::npos);
}

// Radiance past a float (an environment of 1e30 scaled by 1e30): refused, naming the pixel, where it wrote
// infinite pixels with success (issue 47); the same scene at scale 1 renders.
TEST(Render, RadiancePastAFloatIsRefused) {
  const auto scene = [](double scale) {
    return parse_scene_text(R"({"camera": {"width": 8, "height": 8}, "render": {"spp": 1},
        "environment": {"constant": [1e30, 1e30, 1e30], "scale": )" + std::to_string(scale) + R"(},
        "materials": {"m": {"type": "lambert"}}, "objects": [{"type": "sphere", "material": "m"}]})",
                            "bright.json", ".");
  };
  EXPECT_NE(test::error_of([&] { render(scene(1e30)); }).find("bright.json: pixel (0, 0) is brighter than an image holds"), std::string::npos);
  const RenderedImage image = render(scene(1.0));
  EXPECT_TRUE(std::all_of(image.rgba.begin(), image.rgba.end(), [](float v) { return std::isfinite(v); }));
}

TEST(Render, BadScenesGetOneClearLine) {
  test::TempDir dir;
  test::write_bytes(dir.file("a.json"), R"({"objects": [{"type": "sphere", "material": "nope"}]})");
  EXPECT_NE(test::error_of([&] { parse_scene(dir.file("a.json")); }).find("undefined material \"nope\""), std::string::npos);
  // A misspelt key is an error, not a silent default (the audit's "fvo" rendered at the default 30 degrees).
  test::write_bytes(dir.file("typo.json"), R"({"camera": {"fvo": 60}, "materials": {"m": {"type": "lambert"}},
      "objects": [{"type": "sphere", "material": "m"}]})");
  const std::string typo = test::error_of([&] { parse_scene(dir.file("typo.json")); });
  EXPECT_NE(typo.find("typo.json: camera: unknown key \"fvo\" (known: position, look_at, up, fov, width, height)"), std::string::npos)
      << typo;
  test::write_bytes(dir.file("two.json"), R"({"environment": {"builtin": "sky", "constant": [1, 1, 1]}, "materials": {"m": {"type": "lambert"}},
      "objects": [{"type": "sphere", "material": "m"}]})");
  EXPECT_NE(test::error_of([&] { parse_scene(dir.file("two.json")); }).find("environment takes one of"), std::string::npos);
  test::write_bytes(dir.file("b.json"), "[1, 2");
  EXPECT_NE(test::error_of([&] { parse_scene(dir.file("b.json")); }).find("b.json: not valid JSON"), std::string::npos);
  test::write_bytes(dir.file("c.json"),
                    R"({"materials": {"m": {"type": "measured", "file": "missing.binary"}}, "objects": [{"type": "sphere", "material": "m"}]})");
  const std::string missing = test::error_of([&] { render(parse_scene(dir.file("c.json"))); });
  EXPECT_NE(missing.find("missing.binary: cannot open"), std::string::npos) << missing;
  // ... and the scene key that referenced it.
  EXPECT_NE(missing.find("(material \"m\" in " + dir.file("c.json") + ")"), std::string::npos) << missing;
  // Values the ray tracer cannot take are refused with one line naming them (each of these aborted
  // Embree or overflowed the stack before).
  const std::string sphere = R"("materials": {"m": {"type": "lambert"}}, "objects": [{"type": "sphere", "material": "m")";
  const std::pair<std::string, std::string> bad[] = {
      {R"({"camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "up": [0, 0, 1]}, )" + sphere + "}]}", "camera.up must not be parallel"},
      {R"({"camera": {"position": [1, 2, 3], "look_at": [1, 2, 3]}, )" + sphere + "}]}", "camera.look_at must differ"},
      {R"({"camera": {"up": [0, 0, 0]}, )" + sphere + "}]}", "camera.up must not be zero"},
      {R"({"camera": {"position": [1e38, 0, 4]}, )" + sphere + "}]}", "camera.position must have coordinates within"},
      {"{" + sphere + R"(, "center": [1e308, 0, 0]}]})", "sphere center must have coordinates within"},
      {"{" + sphere + R"(, "radius": 1e38}]})", "sphere radius must be in (0, 1e6]"},
      {R"({"materials": {"m": {"type": "lambert"}}, "objects": [{"type": "plane", "material": "m", "normal": [0, 0, 0]}]})",
       "plane normal must not be zero"},
      {R"({"materials": {"m": {"type": "lambert", "albedo": [-1, 0, 0]}}, "objects": [{"type": "sphere", "material": "m"}]})",
       "albedo must be three finite numbers >= 0"},
      {R"({"environment": {"constant": [1, 1, 1], "scale": -2}, )" + sphere + "}]}", "environment.scale must be"},
      {R"({"materials": {"m": {"type": "lambert", "proposal": "x.exr"}}, "objects": [{"type": "sphere", "material": "m"}]})",
       "\"proposal\" is for measured materials"},
      {R"({"objects": )" + std::string(100000, '[') + std::string(100000, ']') + "}", "nested more than 32 levels"},
      // Integers out of range, which nlohmann/json stores as floats: converting them was undefined
      // behaviour (fuzz_scene's finding).
      {R"({"render": {"seed": 100000000000000000000000000000000000000}, )" + sphere + "}]}", "\"seed\" must be an integer between 0 and"},
      {R"({"render": {"seed": -1}, )" + sphere + "}]}", "\"seed\" must be an integer between 0 and"},
      {R"({"render": {"spp": 2.5}, )" + sphere + "}]}", "\"spp\" must be an integer"},
      {R"({"camera": {"width": 1e20}, )" + sphere + "}]}", "\"width\" must be an integer between 1 and 16384"},
      {R"({"camera": {"height": 0}, )" + sphere + "}]}", "\"height\" must be an integer between 1 and 16384"},
  };
  for (const auto& [text, message] : bad) {
    test::write_bytes(dir.file("bad.json"), text);
    const std::string e = test::error_of([&] { parse_scene(dir.file("bad.json")); });
    EXPECT_NE(e.find(message), std::string::npos) << "expected \"" << message << "\", got: " << e.substr(0, 200);
    EXPECT_EQ(e.find('\n'), std::string::npos) << e.substr(0, 200);  // one line
  }
  EXPECT_NE(test::error_of([&] { parse_scene("/dev/zero"); }).find("/dev/zero: not a regular file"), std::string::npos);
  // An integral float is an integer.
  test::write_bytes(dir.file("ok.json"), R"({"camera": {"width": 64.0}, "render": {"seed": 7, "spp": 8}, )" + sphere + "}]}");
  EXPECT_EQ(parse_scene(dir.file("ok.json")).camera.width, 64);
  // A material built in code with an unknown type fails instead of rendering as some other type.
  MaterialDesc odd;
  odd.type = "velvet";
  odd.alpha = 0.3;
  const SceneDesc no_scene = default_scene(MaterialDesc{});  // named: GCC 12 misreads a temporary here
  const std::string unknown = test::error_of([&] { load_material(no_scene, odd); });
  EXPECT_NE(unknown.find("material type 'velvet'"), std::string::npos) << unknown;
}

TEST(Render, ObjMeshes) {
  test::TempDir dir;
  test::write_bytes(dir.file("quad.obj"), "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n");
  std::vector<float> p;
  std::vector<unsigned> idx;
  read_obj(dir.file("quad.obj"), p, idx);
  EXPECT_EQ(p.size(), 12u);
  EXPECT_EQ(idx, (std::vector<unsigned>{0, 1, 2, 0, 2, 3}));
  // Devices are refused before reading (/dev/zero is one endless line; a LUT or map on it hung OpenImageIO).
  EXPECT_NE(test::error_of([&] { read_obj("/dev/zero", p, idx); }).find("/dev/zero: not a regular file"), std::string::npos);
  EXPECT_NE(test::error_of([&] { read_lut("/dev/zero"); }).find("/dev/zero: not a regular file"), std::string::npos);
  test::write_bytes(dir.file("bad.obj"), "v 0 0 0\nf 1 2 3\n");
  p.clear();
  idx.clear();
  EXPECT_NE(test::error_of([&] { read_obj(dir.file("bad.obj"), p, idx); }).find("line 2: vertex index out of range"), std::string::npos);
  // Lines are bounded as they are read (a file of NULs is one endless line), coordinates as a scene's.
  test::write_bytes(dir.file("nul.obj"), std::string(1 << 17, '\0'));
  EXPECT_NE(test::error_of([&] { read_obj(dir.file("nul.obj"), p, idx); }).find("line 1 is longer than 64 KiB"), std::string::npos);
  test::write_bytes(dir.file("far.obj"), "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3");
  EXPECT_NE(test::error_of([&] { read_obj(dir.file("far.obj"), p, idx); }).find("line 2: vertex coordinate outside +-1e6"),
            std::string::npos);
  // The last line needs no newline.
  test::write_bytes(dir.file("last.obj"), "v -1 -1 0\r\nv 1 -1 0\n\nv 1 1 0\nf 1 2 3");
  p.clear();
  idx.clear();
  read_obj(dir.file("last.obj"), p, idx);
  EXPECT_EQ(p.size(), 9u);
  EXPECT_EQ(idx, (std::vector<unsigned>{0, 1, 2}));
}

}  // namespace
}  // namespace facetfit

#include "color/image_diff.h"
#include "io/input.h"
#include "lut/lut.h"

namespace facetfit {
namespace {

// `measured` (builtin:gold-ggx-0.15 as a measurement) and the analytic model rendered in the same
// small scene with the same seeds, compared over the sphere.
ImageDiff measured_against_analytic_gold(const MaterialDesc& measured) {
  MaterialDesc analytic;
  analytic.type = "analytic";
  analytic.file = "builtin:gold-ggx-0.15";
  SceneDesc a = default_scene(measured), b = default_scene(analytic);
  for (SceneDesc* s : {&a, &b}) {
    s->camera.width = s->camera.height = 64;
    s->spp = 64;
  }
  const RenderedImage ia = render(a), ib = render(b);
  std::vector<bool> mask(std::size_t(ia.width) * ia.height);
  for (std::size_t p = 0; p < mask.size(); ++p) mask[p] = ia.rgba[4 * p + 3] >= 1.0f;
  return image_delta_e(ia.rgb(), false, ib.rgb(), false, mask, DisplayTransform());
}

TEST(Render, MeasuredGgxTableMatchesTheAnalyticGgx) {
  // The analytic gold GGX, tabulated into a MERL table and rendered from it (trilinear lookup), against
  // the analytic model itself: mean Delta E 2000 over the sphere < 0.5.
  MaterialDesc measured;
  measured.type = "measured";
  measured.file = "builtin:gold-ggx-0.15";
  const ImageDiff d = measured_against_analytic_gold(measured);
  EXPECT_GT(d.pixels, 1000u);
  EXPECT_LT(d.mean, 0.5);
  std::printf("measured vs analytic GGX: mean Delta E 2000 %.4f, max %.4f over %zu pixels\n", d.mean, d.max, d.pixels);
}

TEST(Render, MeasuredMaterialSampledByAGivenLutRendersTheSameImage) {
  // A measured material sampled by a bake's LUT (the report hands its bake over rather than fitting
  // again) still renders the measurement: the same bar against the analytic model.
  test::TempDir dir;
  write_gold_lut(dir.file("gold.exr"));
  MaterialDesc measured;
  measured.type = "measured";
  measured.file = "builtin:gold-ggx-0.15";
  measured.proposal = dir.file("gold.exr");
  const ImageDiff d = measured_against_analytic_gold(measured);
  EXPECT_GT(d.pixels, 1000u);
  EXPECT_LT(d.mean, 0.5);
  // A missing proposal is an error naming it, not a silent refit.
  measured.proposal = dir.file("none.exr");
  EXPECT_NE(test::error_of([&] { render(default_scene(measured)); }).find("none.exr"), std::string::npos);
}

TEST(Render, StretchedLutMaterials) {
  // The scene's stretch reaches the model (tests/test_stretch.cpp checks the model against the analytic
  // anisotropic GGX): the identity renders the LUT as it is, a stretch changes the image, and bad values
  // get one line.
  test::TempDir dir;
  write_gold_lut(dir.file("gold.exr"));
  const auto scene = [&](const std::string& extra) {
    SceneDesc s = parse_scene_text(R"({"camera": {"width": 32, "height": 32}, "render": {"spp": 8},
      "environment": {"builtin": "sky"},
      "materials": {"m": {"type": "lut", "file": "gold.exr")" + extra + R"(}},
      "objects": [{"type": "sphere", "material": "m"}]})", "s.json", dir.path().string());
    return s;
  };
  const RenderedImage plain = render(scene("")), identity = render(scene(R"(, "stretch": [1, 1], "rotation": 40)"));
  EXPECT_EQ(plain.rgba, identity.rgba);
  const RenderedImage stretched = render(scene(R"(, "stretch": [3, 0.5], "rotation": 30)"));
  double diff = 0.0;
  for (std::size_t k = 0; k < plain.rgba.size(); ++k) diff += std::abs(plain.rgba[k] - stretched.rgba[k]);
  EXPECT_GT(diff / double(plain.rgba.size()), 1e-3);
  EXPECT_NE(test::error_of([&] { scene(R"(, "stretch": [0, 1])"); }).find("stretch must be in [0.01, 100]"), std::string::npos);
  EXPECT_NE(test::error_of([&] { scene(R"(, "stretch": 2)"); }).find("stretch must be [x, y]"), std::string::npos);
  EXPECT_NE(test::error_of([&] {
              parse_scene_text(R"({"materials": {"m": {"type": "ggx", "alpha": 0.2, "stretch": [2, 1]}},
                                   "objects": [{"type": "sphere", "material": "m"}]})", "t.json", ".");
            }).find("are for lut, closures and material materials"), std::string::npos);
}

// A constant environment is lit by the BRDF sample alone, a map by a light sample and a BRDF sample
// weighted by multiple importance sampling (render/integrator.cpp): two estimators of the same integral.
// A map whose every pixel is the constant must then give the same sphere, to the noise, for every kind of
// model: closed-form GGX, tabulated Beckmann, Lambert, a measured table under its fitted proposal, a LUT,
// and a stretched LUT (shaded one pair at a time).
TEST(Render, AConstantEnvironmentAndTheSameMapGiveTheSameSphere) {
  test::TempDir dir;
  write_gold_lut(dir.file("gold.exr"));
  write_texture(dir.file("flat.exr"), 32, 16, [](int, int) { return Rgb(0.3, 0.25, 0.2); });
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

TEST(Render, StretchTextureDrivesTheStretchPerPoint) {
  // A uniform texture (2, 0.5) times a stretch (1.5, 1) is the stretch (3, 0.5) everywhere: the same image,
  // sample for sample. A texture that varies changes the image where it departs from that value.
  test::TempDir dir;
  write_gold_lut(dir.file("gold.exr"));
  write_texture(dir.file("uniform.exr"), 4, 2, [](int, int) { return Rgb(2.0, 0.5, 7.0); });
  // The bottom row as the top: v is periodic, so the top pole reads both.
  write_texture(dir.file("bands.exr"), 16, 8, [](int, int y) { return y < 4 || y == 7 ? Rgb(2.0, 0.5, 0.0) : Rgb(0.5, 2.0, 0.0); });
  const auto scene = [&](const std::string& material, const std::string& object) {
    return parse_scene_text(R"({"camera": {"width": 32, "height": 32}, "render": {"spp": 8},
      "environment": {"builtin": "sky"},
      "materials": {"m": {"type": "lut", "file": "gold.exr", "rotation": 30, "tangent": [0, 1, 0])" + material + R"(}},
      "objects": [)" + object + R"(]})", "s.json", dir.path().string());
  };
  const std::string sphere = R"({"type": "sphere", "material": "m"})";
  const std::string plane = R"({"type": "plane", "point": [0, 0, 0], "normal": [0, 0.6, 4], "size": 2, "material": "m"})";
  for (const std::string& object : {sphere, plane}) {
    const RenderedImage fixed = render(scene(R"(, "stretch": [3, 0.5])", object));
    const RenderedImage textured = render(scene(R"(, "stretch": [1.5, 1], "stretch_texture": "uniform.exr")", object));
    EXPECT_EQ(fixed.rgba, textured.rgba) << object;
    // Bands: the upper half of the texture (v > 1/2: the upper hemisphere, or half the plane) is (2, 0.5),
    // most of the lower (0.5, 2).
    const RenderedImage bands = render(scene(R"(, "stretch": [1.5, 1], "stretch_texture": "bands.exr")", object));
    EXPECT_NE(fixed.rgba, bands.rgba) << object;
  }
  // On the sphere the upper rows see the upper texture band: identical to the uniform stretch where the
  // whole bilinear footprint lies in that band (the top rows of the sphere, well above its equator).
  const RenderedImage fixed = render(scene(R"(, "stretch": [3, 0.5])", sphere));
  const RenderedImage bands = render(scene(R"(, "stretch": [1.5, 1], "stretch_texture": "bands.exr")", sphere));
  int same = 0, covered = 0;
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 32; ++x) {
      const std::size_t k = (std::size_t(y) * 32 + std::size_t(x)) * 4;
      if (fixed.rgba[k + 3] < 1.0f) continue;
      ++covered;
      same += fixed.rgba[k] == bands.rgba[k] && fixed.rgba[k + 1] == bands.rgba[k + 1];
    }
  EXPECT_GT(covered, 20);
  EXPECT_EQ(same, covered);
  EXPECT_NE(test::error_of([&] { render(scene(R"(, "stretch_texture": "missing.exr")", sphere)); }).find("missing.exr"), std::string::npos);
  write_texture(dir.file("nan.exr"), 2, 2, [](int x, int y) { return x == 1 && y == 1 ? Rgb(1.0, std::nan(""), 1.0) : Rgb(1.0); });
  EXPECT_NE(test::error_of([&] { render(scene(R"(, "stretch_texture": "nan.exr")", sphere)); }).find("nan.exr: non-finite G value at pixel (1, 1)"),
            std::string::npos);
  EXPECT_NE(test::error_of([&] { scene(R"(, "stretch_texture": "uniform.exr")", R"({"type": "mesh", "file": "x.obj", "material": "m"})"); })
                .find("a mesh has no texture coordinates"),
            std::string::npos);
}

// A unit sphere of `material` (scene-format JSON) under the built-in sky, size x size pixels, files
// resolved in `dir`.
RenderedImage sphere_under_sky(const test::TempDir& dir, const std::string& material, int size, int spp) {
  return render(parse_scene_text(R"({"camera": {"width": )" + std::to_string(size) + R"(, "height": )" + std::to_string(size) +
                                     R"(}, "render": {"spp": )" + std::to_string(spp) + R"(}, "environment": {"builtin": "sky"},
      "materials": {"m": )" + material + R"(}, "objects": [{"type": "sphere", "material": "m"}]})",
                                 "s.json", dir.path().string()));
}

// Sum of |a - b| over the sum of a, every channel.
double relative_difference(const RenderedImage& a, const RenderedImage& b) {
  double d = 0.0, sum = 0.0;
  for (std::size_t k = 0; k < a.rgba.size(); ++k) d += std::abs(a.rgba[k] - b.rgba[k]), sum += a.rgba[k];
  return d / sum;
}

// A UTIA file renders as itself, anisotropic (its fit, of the azimuthal mean, only proposes directions):
// the material's tangent turns the highlight, which it cannot do to an isotropic file.
TEST(Render, MeasuredUtiaFilesRenderAnisotropicAlongTheirTangent) {
  test::TempDir dir;
  const MicrofacetBrdf aniso(Ndf{NdfType::ggx, 0.5, 0.2}, Smith::correlated, Fresnel::schlick(Rgb(0.9, 0.7, 0.4)));
  const MicrofacetBrdf iso(Ndf::isotropic(NdfType::ggx, 0.35), Smith::correlated, Fresnel::schlick(Rgb(0.9, 0.7, 0.4)));
  UtiaBrdf::tabulate(aniso).write(dir.file("aniso.bin"));
  UtiaBrdf::tabulate(iso).write(dir.file("iso.bin"));
  const auto image = [&](const std::string& file, const std::string& tangent) {
    return sphere_under_sky(dir, R"({"type": "measured", "file": ")" + file + R"(", "tangent": )" + tangent + "}", 32, 16);
  };
  const double turned_aniso = relative_difference(image("aniso.bin", "[0, 1, 0]"), image("aniso.bin", "[1, 0, 0]"));
  const double turned_iso = relative_difference(image("iso.bin", "[0, 1, 0]"), image("iso.bin", "[1, 0, 0]"));
  std::cout << "relative change when the tangent turns: anisotropic " << turned_aniso << ", isotropic " << turned_iso << "\n";
  EXPECT_GT(turned_aniso, 4.0 * turned_iso);  // 0.087 against 0.012 when written
}

// A LUT baked from an anisotropic file carries the anisotropic lobe (LUT version 3): rendered along the
// tangent, it is nearer the file itself than the LUT's isotropic lobe of the azimuthal mean. The file is
// an RGL one (the tests' tensor writer: GGX 0.45 x 0.2 turned 30 degrees, F = 1), whose evaluation is
// accurate to the model; a UTIA file's 15-degree grid blurs such a lobe more than the fit misses it.
TEST(Render, AnisotropicLutRendersNearerItsMeasurementThanTheIsotropicLobe) {
  test::TempDir dir;
  const std::vector<unsigned char> bytes =
      test::serialize(test::microfacet_tensor_fields(Ndf{NdfType::ggx, 0.45, 0.2}, Smith::correlated, 30.0 * kPi / 180.0, 25, 32, 64));
  test::write_bytes(dir.file("aniso.bsdf"), std::string(bytes.begin(), bytes.end()));
  const FitResult fit = Fitter{FitOptions{}}.fit(load_table(dir.file("aniso.bsdf")));
  ASSERT_TRUE(fit.ok() && fit.anisotropic.has_value()) << fit.problem;
  write_lut(dir.file("aniso.exr"), make_lut(fit, Quadrature(90), "aniso.bsdf", "", 0.05, true));
  const Lut lut = read_lut(dir.file("aniso.exr"));
  ASSERT_TRUE(lut.anisotropic.has_value());
  // Version 5 (the closures), with the anisotropic rows.
  EXPECT_EQ(lut.meta.format_version, kLutClosuresVersion);
  const auto image = [&](const std::string& material) { return sphere_under_sky(dir, material, 32, 1024); };
  const std::string tangent = R"("tangent": [0.6, 0.8, 0])";
  const RenderedImage measured = image(R"({"type": "measured", "file": "aniso.bsdf", "proposal": "aniso.exr", )" + tangent + "}");
  const double anisotropic = relative_difference(image(R"({"type": "lut", "file": "aniso.exr", )" + tangent + "}"), measured);
  const double isotropic = relative_difference(image(R"({"type": "lut", "file": "aniso.exr", "anisotropic": false, )" + tangent + "}"), measured);
  const double turned = relative_difference(image(R"({"type": "lut", "file": "aniso.exr", "tangent": [-0.8, 0.6, 0]})"), measured);
  // The anisotropic GGX fit (a ggx material with the LUT) too, and its isotropic GGX.
  const double ggx = relative_difference(image(R"({"type": "ggx", "file": "aniso.exr", )" + tangent + "}"), measured);
  const double ggx_isotropic = relative_difference(image(R"({"type": "ggx", "file": "aniso.exr", "anisotropic": false, )" + tangent + "}"), measured);
  std::cout << "relative difference from the measured file: anisotropic lobe " << anisotropic << ", isotropic " << isotropic
            << ", anisotropic turned a quarter " << turned << "; anisotropic GGX fit " << ggx << ", isotropic GGX fit " << ggx_isotropic << "\n";
  EXPECT_LT(anisotropic, 0.5 * isotropic);
  EXPECT_LT(anisotropic, 0.5 * turned);
  EXPECT_LT(ggx, 0.5 * ggx_isotropic);
  // The artist's stretch reshapes the anisotropic lobe too (the lobe's own test: model/tabulated_anisotropic.h,
  // tests/test_anisotropic.cpp), uniformly or from a texture: a uniform texture (2, 0.5) times (1.5, 1) is
  // (3, 0.5) everywhere, sample for sample.
  write_texture(dir.file("uniform.exr"), 4, 2, [](int, int) { return Rgb(2.0, 0.5, 7.0); });
  const auto quick = [&](const std::string& material) { return sphere_under_sky(dir, material, 24, 8); };
  const RenderedImage plain = quick(R"({"type": "lut", "file": "aniso.exr", )" + tangent + "}");
  const RenderedImage fixed = quick(R"({"type": "lut", "file": "aniso.exr", "stretch": [3, 0.5], "rotation": 20, )" + tangent + "}");
  const RenderedImage textured =
      quick(R"({"type": "lut", "file": "aniso.exr", "stretch": [1.5, 1], "rotation": 20, "stretch_texture": "uniform.exr", )" + tangent + "}");
  EXPECT_EQ(fixed.rgba, textured.rgba);
  EXPECT_GT(relative_difference(fixed, plain), 0.05);
}

// The plane's texture axes as docs/scene-format.md states them: facing +y, u along +x and v along -z. Seen
// from above (image right +x, image top -z), a texture split in two halves renders each half of the image as
// the uniform stretch of that half does.
TEST(Render, PlaneTextureAxesAreAsDocumented) {
  test::TempDir dir;
  write_gold_lut(dir.file("gold.exr"));
  constexpr int kTexels = 64;
  const auto write_halves = [&](const std::string& name, bool along_u) {
    write_texture(dir.file(name), kTexels, kTexels, [&](int x, int y) {
      // u >= 1/2 (right columns), or v >= 1/2 (top rows): the rough half.
      const bool rough = along_u ? x >= kTexels / 2 : y < kTexels / 2;
      return rough ? Rgb(4.0, 4.0, 0.0) : Rgb(0.25, 0.25, 0.0);
    });
  };
  write_halves("u.exr", true);
  write_halves("v.exr", false);
  constexpr int kSize = 32;
  const auto image = [&](const std::string& material) {
    return render(parse_scene_text(R"({"camera": {"position": [0, 4, 0], "look_at": [0, 0, 0], "up": [0, 0, -1], "width": 32, "height": 32},
      "render": {"spp": 4}, "environment": {"builtin": "sky"},
      "materials": {"m": {"type": "lut", "file": "gold.exr")" + material + R"(}},
      "objects": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "size": 2, "material": "m"}]})",
                                   "s.json", dir.path().string()));
  };
  const RenderedImage sharp = image(R"(, "stretch": [0.25, 0.25])"), rough = image(R"(, "stretch": [4, 4])");
  // Pixel (x, y) sees the plane at world x or -z = (2 (p + 0.5) / 32 - 1) tan(15 deg) 4: compare the pixels
  // well inside one half (0.1 to 0.9 from the middle line), away from the texture's seams.
  const auto world = [](int p) { return (2.0 * (p + 0.5) / kSize - 1.0) * std::tan(15.0 * kPi / 180.0) * 4.0; };
  for (const bool along_u : {true, false}) {
    const RenderedImage textured = image(R"(, "stretch_texture": ")" + std::string(along_u ? "u.exr" : "v.exr") + "\"");
    int checked = 0;
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x) {
        // Column x sees world x = world(x), along which u grows; row y sees world z = world(y), against which v grows.
        const double from_middle = along_u ? world(x) : -world(y);  // > 0: the rough half
        if (std::abs(from_middle) < 0.1 || std::abs(from_middle) > 0.9) continue;
        const RenderedImage& want = from_middle > 0.0 ? rough : sharp;
        const std::size_t k = (std::size_t(y) * kSize + std::size_t(x)) * 4;
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(textured.rgba[k + std::size_t(c)], want.rgba[k + std::size_t(c)], 1e-5 * (1.0 + want.rgba[k + std::size_t(c)]))
              << (along_u ? "u" : "v") << " at pixel " << x << ", " << y;
        ++checked;
      }
    EXPECT_GT(checked, 300);
  }
}

TEST(Texture, BilinearBetweenPixelCentresWithVFromTheBottomAndBothAxesPeriodic) {
  // 4 x 2: row 0 (top) 0, 1, 2, 3 in red; row 1 (bottom) 10, 11, 12, 13.
  const Texture t(4, 2, {0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 10, 0, 0, 11, 0, 0, 12, 0, 0, 13, 0, 0});
  EXPECT_DOUBLE_EQ(t.lookup({0.125, 0.25}).r, 10.0);  // centre of the bottom-left pixel
  EXPECT_DOUBLE_EQ(t.lookup({0.375, 0.75}).r, 1.0);   // centre of the top row's second pixel
  EXPECT_DOUBLE_EQ(t.lookup({0.25, 0.75}).r, 0.5);    // between two centres
  EXPECT_DOUBLE_EQ(t.lookup({0.0, 0.75}).r, 1.5);     // across the u seam: (3 + 0) / 2
  EXPECT_DOUBLE_EQ(t.lookup({0.125, 0.5}).r, 5.0);    // halfway between the rows
  EXPECT_DOUBLE_EQ(t.lookup({1.125, -0.75}).r, 10.0); // periodic
  // The sphere's coordinates: the top pole v = 1, the bottom 0, the point facing +z (the default camera) u = 0.
  EXPECT_NEAR(sphere_texture_coordinates({0, 1, 0}).v, 1.0, 1e-12);
  EXPECT_NEAR(sphere_texture_coordinates({0, -1, 0}).v, 0.0, 1e-12);
  EXPECT_NEAR(sphere_texture_coordinates({1, 0, 0}).v, 0.5, 1e-12);
  EXPECT_NEAR(sphere_texture_coordinates({1, 0, 0}).u, 0.25, 1e-12);
}

}  // namespace
}  // namespace facetfit

#include "core/memory_budget.h"

namespace facetfit {
namespace {

TEST(MemoryBudget, SizesParseAndRendersOverTheBudgetAreRefusedBeforeAllocating) {
  EXPECT_EQ(parse_byte_size("512M"), std::uint64_t(512) << 20);
  EXPECT_EQ(parse_byte_size("4G"), std::uint64_t(4) << 30);
  EXPECT_EQ(parse_byte_size("1.5GiB"), std::uint64_t(3) << 29);
  EXPECT_EQ(parse_byte_size("2KB"), 2048u);
  EXPECT_EQ(parse_byte_size("1000"), 1000u);
  for (const char* bad : {"", "G", "-1G", "0", "1X", "nanG", "1e30T", "4 G", "0x10G", " 4G", "0x1p4M"}) EXPECT_FALSE(parse_byte_size(bad)) << bad;
  EXPECT_GT(default_memory_budget(), 0u);

  // An image over the budget: one line, before any buffer exists (16384^2 would take 15 GiB).
  MaterialDesc lambert;
  SceneDesc big = default_scene(lambert);
  big.camera.width = big.camera.height = 16384;
  RenderSettings settings;
  settings.max_memory = std::uint64_t(1) << 30;
  EXPECT_NE(test::error_of([&] { render(big, settings); }).find("render: a 16384 x 16384 image needs 15.0 GiB, over the memory budget of 1.0 GiB"),
            std::string::npos);
  // A 65536 x 32768 environment map announced by a 60-byte Radiance header (it asked for 24 GiB and
  // ended in std::bad_alloc): refused from its header, under the default budget too.
  test::TempDir dir;
  test::write_bytes(dir.file("huge.hdr"), "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 32768 +X 65536\n\x02\x02");
  SceneDesc sky = default_scene(lambert);
  sky.camera.width = sky.camera.height = 8;
  sky.environment.kind = EnvironmentDesc::Kind::file;
  sky.environment.file = dir.file("huge.hdr");
  const std::string e = test::error_of([&] { render(sky); });
  EXPECT_NE(e.find("huge.hdr: a 65536 x 32768 environment map needs"), std::string::npos) << e;
  EXPECT_NE(e.find("over the memory budget"), std::string::npos) << e;
}

// Meshes count against the budget as their files are read (issue 61: a 21 MB OBJ took 1.1 GB under
// --max-memory 64M): a grid of 20,000 triangles (about 2 MB to render: mesh_bytes) renders under 64 MiB and is
// refused under 1 MiB, naming the file; two grids of 12,800 under 2 MiB pass one at a time and not together.
TEST(Render, MeshesCountAgainstTheMemoryBudget) {
  test::TempDir dir;
  const auto grid = [&](const std::string& name, int n) {
    std::ostringstream obj;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j) obj << "v " << double(i) / n - 0.5 << " 0 " << double(j) / n - 0.5 << "\n";
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const int a = i * (n + 1) + j + 1;
        obj << "f " << a << " " << a + 1 << " " << a + n + 2 << " " << a + n + 1 << "\n";
      }
    test::write_bytes(dir.file(name), obj.str());
  };
  grid("big.obj", 100);
  grid("a.obj", 80);
  grid("b.obj", 80);
  const auto scene = [&](const std::string& objects) {
    return parse_scene_text(R"({"camera": {"position": [0, 2, 2], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 40, "width": 8, "height": 8},
                               "materials": {"m": {"type": "lambert"}}, "objects": [)" + objects + "]}",
                            dir.file("s.json"), dir.path().string());
  };
  const auto mesh = [](const std::string& file) { return R"({"type": "mesh", "file": ")" + file + R"(", "material": "m"})"; };
  RenderSettings settings;
  settings.spp = 1;
  settings.max_memory = std::uint64_t(64) << 20;
  EXPECT_NO_THROW(render(scene(mesh("big.obj")), settings));
  settings.max_memory = std::uint64_t(1) << 20;
  const std::string e = test::error_of([&] { render(scene(mesh("big.obj")), settings); });
  EXPECT_NE(e.find("big.obj: a mesh of "), std::string::npos) << e;
  EXPECT_NE(e.find("over the memory budget of "), std::string::npos) << e;  // what the image and materials left
  EXPECT_GT(mesh_bytes(101 * 101, 20000), std::uint64_t(1) << 20);
  settings.max_memory = std::uint64_t(2) << 20;
  EXPECT_NO_THROW(render(scene(mesh("a.obj")), settings));
  EXPECT_NE(test::error_of([&] { render(scene(mesh("a.obj") + ", " + mesh("b.obj")), settings); }).find("b.obj: a mesh of"), std::string::npos);
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
