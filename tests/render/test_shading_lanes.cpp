// The shading models in SIMD lanes (render/ggx_batch.h, lambert_batch.h, tabulated_batch.h, merl_batch.h)
// against ShadingModel one pair at a time on every SIMD target; every material type of the registry in the
// lanes it declares, and converting every colour it has to another working space.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "fit/fit.h"
#include "io/input.h"
#include "lut/lut.h"
#include "model/analytic.h"
#include "model/parametric.h"
#include "model/proposal.h"
#include "model/tabulated.h"
#include "model/visible_slopes.h"
#include "render/ggx_batch.h"
#include "render/lambert_batch.h"
#include "render/merl_batch.h"
#include "render/materials.h"
#include "render/scene.h"
#include "render/shading.h"
#include "render/simd_targets.h"
#include "render/tabulated_batch.h"
#include "render_fixtures.h"
#include "test_util.h"

namespace facetfit {
namespace {

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

// Every material type of the registry (render/scene.h) in its plain form runs on the stream path as it
// declares: sampling and density in SIMD lanes, and f too where it says `all`. A type whose models leave the
// lanes (a new model without kernels, a proposal they do not hold) fails here instead of rendering one
// pair at a time unseen. The loop reads the registry, so a new type is tested as soon as it is listed.
TEST(Shading, EveryMaterialTypeRunsInTheLanesItDeclares) {
  test::TempDir dir;
  const std::string lut = dir.file("gold.exr");
  test::write_gold_lut(lut);
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

}  // namespace
}  // namespace facetfit
