// Numerical stability: extreme roughness and Fresnel, missing samples, noise, degenerate inputs.
// Nothing may produce NaN or Inf; a meaningless fit is reported as such.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "fit/fit.h"
#include "fit/recommend.h"
#include "io/input.h"
#include "io/utia.h"
#include "lut/lut.h"
#include "model/analytic.h"
#include "model/parametric.h"
#include "model/proposal.h"
#include "model/tabulated.h"
#include "model/visible_slopes.h"
#include "render/camera_batch.h"
#include "render/ggx_batch.h"
#include "render/merl_batch.h"
#include "render/shading.h"
#include "render/scene.h"
#include "render/tabulated_batch.h"
#include "test_util.h"

namespace facetfit {
namespace {

bool finite(double x) { return std::isfinite(x); }
bool finite(const Rgb& c) { return finite(c.r) && finite(c.g) && finite(c.b); }

// Every number a fit exposes is finite, whether or not the fit is meaningful.
void expect_all_finite(const FitResult& r) {
  for (double v : r.ndf().ndf) ASSERT_TRUE(finite(v) && v >= 0.0);
  for (double v : r.ndf().sigma) ASSERT_TRUE(finite(v) && v >= 0.0);
  for (const Rgb& v : r.fresnel().value) ASSERT_TRUE(finite(v));
  EXPECT_TRUE(finite(r.alpha_ggx) && finite(r.alpha_beckmann) && finite(r.f0) && finite(r.f82));
  EXPECT_TRUE(finite(r.extraction.eigenvalue) && finite(r.extraction.residual));
  // The tabulated model itself, at grazing angles too.
  for (double theta : {0.0, 1e-6, 1.0, 1.5, 1.5707, 0.5 * kPi}) {
    EXPECT_TRUE(finite(r.ndf().D(theta)));
    EXPECT_TRUE(finite(r.ndf().g1(std::cos(theta))));
  }
}

FitResult fit(const HalfDiffTable& table, Smith smith = Smith::correlated) {
  FitOptions options = FitOptions::paper();
  options.smith = smith;
  return Fitter(options).fit(table);
}

HalfDiffTable table_of(NdfType type, double alpha, const Fresnel& fresnel) {
  return HalfDiffTable::tabulate(MicrofacetBrdf(Ndf::isotropic(type, alpha), Smith::correlated, fresnel));
}

class ExtremeRoughness : public testing::TestWithParam<std::tuple<NdfType, double>> {};

TEST_P(ExtremeRoughness, FiniteAndClose) {
  const auto [type, alpha] = GetParam();
  const FitResult r = fit(table_of(type, alpha, Fresnel::schlick(Rgb(0.5))));
  ASSERT_TRUE(r.ok()) << r.problem;
  expect_all_finite(r);
  const double fitted = type == NdfType::ggx ? r.alpha_ggx : r.alpha_beckmann;
  // The grid resolves alpha = 0.005 with about five nodes: a percent is what it can do.
  EXPECT_NEAR(fitted, alpha, alpha * (alpha < 0.01 ? 0.015 : 0.005));
}

INSTANTIATE_TEST_SUITE_P(Alpha, ExtremeRoughness,
                         testing::Combine(testing::Values(NdfType::ggx, NdfType::beckmann),
                                          testing::Values(0.005, 0.01, 1.2, 1.5)));

// The coarsest grid a fit accepts, on the narrowest lobes: either a fit whose moment alphas and distances
// are positive and finite, recommending a representation with a finite distance, or a problem that says
// to raise --resolution. Nothing coarser is accepted.
TEST(Stress, CoarsestResolutionOnNarrowLobes) {
  for (int resolution : {kMinResolution, 24})
    for (double alpha : {0.005, 0.02, 0.05}) {
      FitOptions options = FitOptions::paper();
      options.resolution = resolution;
      const FitResult r = Fitter(options).fit(table_of(NdfType::ggx, alpha, Fresnel::schlick(Rgb(0.9))));
      SCOPED_TRACE("resolution " + std::to_string(resolution) + ", alpha " + std::to_string(alpha));
      if (!r.ok()) {
        EXPECT_NE(r.problem.find("raise --resolution"), std::string::npos) << r.problem;
        continue;
      }
      expect_all_finite(r);
      EXPECT_GT(r.alpha_ggx, 0.0);
      EXPECT_GT(r.alpha_beckmann, 0.0);
      for (double error : {r.error, r.ggx.error, r.beckmann.error}) EXPECT_TRUE(finite(error));
      EXPECT_TRUE(finite(parameters_of(r, recommend(r, kDefaultTolerance)).error));
    }
  FitOptions coarse = FitOptions::paper();
  coarse.resolution = kMinResolution - 1;
  EXPECT_THROW(Fitter{coarse}, Error);
}

// A distance that is NaN (a parametric fit that failed) never wins the recommendation.
TEST(Stress, ANaNDistanceIsNeverRecommended) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(recommend(0.2, 0.133, nan, 0.0, 0.02), Representation::ggx);
  EXPECT_EQ(recommend(0.2, nan, 0.133, 0.0, 0.02), Representation::beckmann);
  EXPECT_EQ(recommend(0.2, nan, nan, 0.0, 0.02), Representation::tabulated);
  EXPECT_EQ(recommend(nan, 0.1, 0.1, 0.0, 0.02), Representation::tabulated);
  EXPECT_EQ(recommend(0.2, 0.15, 0.14, 0.0, 0.02), Representation::beckmann);  // control: both finite, nearer wins
  EXPECT_EQ(recommend(0.2, 0.3, 0.3, nan, 0.02), Representation::tabulated);
  EXPECT_EQ(recommend(0.2, 0.3, 0.3, 0.15, 0.02), Representation::closures);  // control: the closures nearest
}

// The cheapest representation within the tolerance of the nearest: a one-lobe fit over the closures over the
// tabulated lobe; closures that were not fitted (distance 0, --refine none) are not a candidate.
TEST(Stress, RecommendationIsTheCheapestNearEnough) {
  EXPECT_EQ(recommend(0.100, 0.102, 0.2, 0.101, 0.02), Representation::ggx);
  EXPECT_EQ(recommend(0.100, 0.2, 0.2, 0.1019, 0.02), Representation::closures);  // within 2%
  // Within 0.2 L* units (0.2 / 116 = 0.00172) where 2% is less, and just beyond it.
  EXPECT_EQ(recommend(0.010, 0.2, 0.2, 0.0117, 0.02), Representation::closures);
  EXPECT_EQ(recommend(0.010, 0.2, 0.2, 0.0118, 0.02), Representation::tabulated);
  EXPECT_EQ(recommend(0.100, 0.2, 0.2, 0.2, 0.02), Representation::tabulated);
  EXPECT_EQ(recommend(0.2, 0.1, 0.2, 0.0, 0.02), Representation::ggx);
  EXPECT_EQ(recommend(0.2, 0.3, 0.3, 0.0, 0.02), Representation::tabulated);
}

TEST(Stress, FresnelFromDarkToWhite) {
  for (double f0 : {0.01, 0.04, 0.3, 1.0}) {
    const FitResult r = fit(table_of(NdfType::ggx, 0.2, Fresnel::schlick(Rgb(f0))));
    ASSERT_TRUE(r.ok());
    expect_all_finite(r);
    EXPECT_NEAR(r.f0.g, f0, 0.005 * std::max(f0, 0.1)) << "f0 " << f0;
    EXPECT_NEAR(r.alpha_ggx, 0.2, 0.001);
  }
}

TEST(Stress, ThirtyPercentMissing) {
  HalfDiffTable table = table_of(NdfType::ggx, 0.3, Fresnel::conductor({0.2, 0.9, 1.1}, {3.9, 2.4, 2.1}));
  std::mt19937 rng(1);
  std::bernoulli_distribution drop(0.3);
  for (int i = 0; i < HalfDiffTable::kThetaH; ++i)
    for (int j = 0; j < HalfDiffTable::kThetaD; ++j)
      for (int k = 0; k < HalfDiffTable::kPhiD; ++k)
        if (drop(rng)) table.set_missing(i, j, k);
  const FitResult r = fit(table);
  ASSERT_TRUE(r.ok()) << r.problem;
  expect_all_finite(r);
  EXPECT_NEAR(r.alpha_ggx, 0.3, 0.3 * 0.005);
  const Rgb truth = fresnel_conductor({0.2, 0.9, 1.1}, {3.9, 2.4, 2.1}, 1.0);
  EXPECT_NEAR(r.f0.r, truth.r, 0.005);
  for (const auto& count : r.fresnel().count) EXPECT_GT(count[0], 0);
}

TEST(Stress, WholeBackScatteringRowsMissing) {
  HalfDiffTable table = table_of(NdfType::beckmann, 0.2, Fresnel::schlick(Rgb(0.8)));
  for (int i = 10; i < 30; i += 3)
    for (int k = 0; k < HalfDiffTable::kPhiD; ++k) table.set_missing(i, 0, k);
  const FitResult r = fit(table);
  ASSERT_TRUE(r.ok());
  expect_all_finite(r);
  EXPECT_NEAR(r.alpha_beckmann, 0.2, 0.2 * 0.02);
}

TEST(Stress, MultiplicativeNoise) {
  HalfDiffTable table = table_of(NdfType::ggx, 0.25, Fresnel::schlick(Rgb(0.9, 0.7, 0.4)));
  std::mt19937 rng(2);
  std::lognormal_distribution<float> noise(0.0f, 0.1f);  // about 10% per measurement
  for (int c = 0; c < 3; ++c)
    for (std::size_t n = 0; n < HalfDiffTable::kBins; ++n)
      if (!HalfDiffTable::missing(table.channel(c)[n])) table.channel(c)[n] *= noise(rng);
  const FitResult r = fit(table);
  ASSERT_TRUE(r.ok());
  expect_all_finite(r);
  EXPECT_NEAR(r.alpha_ggx, 0.25, 0.25 * 0.03);
  EXPECT_NEAR(r.f0.r, 0.9 * std::exp(0.005), 0.02);  // E[lognormal(0, 0.1)] = exp(0.005)
}

// The default fit (refinement and the anisotropic fits) of UTIA files read at their own nodes, at both
// ends of the roughness range, with additive noise that makes the dark channel's entries negative.
TEST(Stress, NoisyUtiaFilesAtExtremeRoughness) {
  for (double alpha : {0.005, 1.5}) {
    const SumBrdf truth({std::make_shared<LambertBrdf>(Rgb(0.3, 0.1, 0.002)),
                         std::make_shared<MicrofacetBrdf>(Ndf::isotropic(NdfType::ggx, alpha), Smith::correlated, Fresnel::schlick(Rgb(0.04)))});
    const std::string path = testing::TempDir() + "/noisy_utia.bin";
    UtiaBrdf::tabulate(truth).write(path);
    std::string bytes = test::read_bytes(path);
    std::vector<double> v(bytes.size() / sizeof(double));
    std::memcpy(v.data(), bytes.data(), bytes.size());
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 2e-4);  // file units: about 0.002 / sr near zero
    for (double& x : v) x += noise(rng);
    std::memcpy(bytes.data(), v.data(), bytes.size());
    test::write_bytes(path, bytes);
    FitOptions options;
    options.refine = FitOptions::Refine::full;
    const FitResult r = Fitter(options).fit(load_table(path));
    SCOPED_TRACE("alpha " + std::to_string(alpha));
    ASSERT_TRUE(r.ok()) << r.problem;
    expect_all_finite(r);
    EXPECT_TRUE(finite(r.body()) && finite(r.error) && finite(r.ggx.alpha) && finite(r.ggx.body) && finite(r.lsq.alpha));
    EXPECT_LE(r.error, r.error_extraction);
    ASSERT_TRUE(r.anisotropic);
    EXPECT_TRUE(finite(r.anisotropic->ggx.alpha.alpha_x) && finite(r.anisotropic->ggx.alpha.alpha_y) && finite(r.anisotropic->ggx.error));
  }
}

TEST(Stress, AllZeroInputIsMeaningless) {
  HalfDiffTable table = table_of(NdfType::ggx, 0.3, Fresnel::one());
  for (int c = 0; c < 3; ++c)
    for (std::size_t n = 0; n < HalfDiffTable::kBins; ++n)
      if (!HalfDiffTable::missing(table.channel(c)[n])) table.channel(c)[n] = 0.0f;
  for (Smith smith : {Smith::masking, Smith::correlated, Smith::separable}) {
    const FitResult r = fit(table, smith);
    EXPECT_FALSE(r.ok());
    EXPECT_NE(r.problem.find("no back-scattered signal"), std::string::npos) << r.problem;
    expect_all_finite(r);
  }
}

TEST(Stress, AllMissingInputIsMeaningless) {
  const FitResult r = fit(HalfDiffTable());
  EXPECT_FALSE(r.ok());
  expect_all_finite(r);
}

TEST(Stress, PureLambertianStaysFinite) {
  // Not a microfacet material: the numbers mean little, but they are numbers.
  for (Smith smith : {Smith::masking, Smith::correlated, Smith::separable}) {
    const FitResult r = fit(HalfDiffTable::tabulate(LambertBrdf(Rgb(0.8))), smith);
    expect_all_finite(r);
    EXPECT_TRUE(r.ok()) << r.problem;
  }
}

TEST(Stress, SeparableAndMaskingAtExtremes) {
  for (Smith smith : {Smith::masking, Smith::separable})
    for (double alpha : {0.005, 1.5}) {
      const FitResult r = fit(HalfDiffTable::tabulate(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, alpha), smith, Fresnel::one())), smith);
      ASSERT_TRUE(r.ok());
      expect_all_finite(r);
      EXPECT_NEAR(r.alpha_ggx, alpha, alpha * 0.015);
    }
}

TEST(GgxLanes, EveryBatchLengthAndDegenerateDirectionStayFiniteAndInBounds) {
  // The SIMD kernels read and write whole vectors up to the padded length (render/shading_batch.h): under
  // the sanitizers of this label, any length from 0 to 40 shows an over-read. Directions on the horizon,
  // opposite pairs, the normal itself and alpha from 0.005 to 1.5: no NaN or Inf escapes, and nothing is
  // found for a view on or below the horizon.
  const Vec3 degenerate[] = {{0, 0, 1}, {1, 0, 0}, {0, -1, 0}, {0.6, 0, 0.8}, {-0.6, 0, -0.8}, {0, 0, -1}, {1e-300, 0, 1}, {0.9999999, 0, 1e-12}};
  FresnelCurve curve;
  for (auto& v : curve.value) v = Rgb(0.5, 0.6, 0.7);
  for (const double alpha : {0.005, 0.3, 1.5})
    for (const bool layered : {false, true}) {
      const Ndf ndf = Ndf::isotropic(NdfType::ggx, alpha);
      const Rgb body = layered ? Rgb(0.2) : Rgb(0.0);
      const Coat coat = layered ? Coat{0.005, 0.04} : Coat{};
      const ShadingModel model(std::make_shared<ParametricBrdf>(ndf, Smith::correlated, curve, body, coat),
                               std::make_shared<GgxProposal>(alpha, Rgb(0.5), body, coat));
      ASSERT_TRUE(model.lanes<GgxLanes>());
      for (std::size_t n = 0; n <= 40; ++n)
        for (const SimdTarget target : kSimdTargets) {
          EvaluationBatch e;
          SampleBatch s;
          for (std::size_t k = 0; k < n; ++k) {
            const Vec3 o = glm::normalize(degenerate[k % 8]), i = glm::normalize(degenerate[(k * 3 + 1) % 8]);
            e.push(o, i);
            s.push(o, double(k % 5) / 5.0, double(k % 7) / 7.0, double(k % 3) / 3.0);
          }
          eval_ggx_batch(model.lanes<GgxLanes>()->model, e, target);
          sample_ggx_batch(model.lanes<GgxLanes>()->model, s, target);
          for (std::size_t k = 0; k < n; ++k) {
            for (const double v : {e.r[k], e.g[k], e.b[k], e.pdf[k]}) ASSERT_TRUE(std::isfinite(v)) << "alpha " << alpha << " pair " << k;
            if (!(e.oz[k] > 0.0 && e.iz[k] > 0.0)) {
              EXPECT_EQ(e.pdf[k], 0.0);
            }
            if (s.found[k] != 0.0) {
              EXPECT_GT(s.oz[k], 0.0);
              for (const double v : {s.ix[k], s.iy[k], s.iz[k]}) ASSERT_TRUE(std::isfinite(v)) << "alpha " << alpha << " sample " << k;
            }
          }
        }
    }
}

TEST(TabulatedLanes, EveryBatchLengthAndDegenerateDirectionStayFiniteAndInBounds) {
  // As above for a LUT's kernels (render/tabulated_batch.h), whose grid lookups gather: an index past a
  // table shows under the sanitizers. The NDF from a peak a node wide to a flat one, and all zero (no facet
  // visible: the slopes' rows uniform, sigma zero). The sampler too, whose search of the running sums runs
  // until every lane has closed its bracket: numbers at 0 and just below 1, on a guide entry.
  const Vec3 degenerate[] = {{0, 0, 1}, {1, 0, 0}, {0, -1, 0}, {0.6, 0, 0.8}, {-0.6, 0, -0.8}, {0, 0, -1}, {1e-300, 0, 1}, {0.9999999, 0, 1e-12}};
  FresnelCurve curve;
  for (auto& v : curve.value) v = Rgb(0.5, 0.6, 0.7);
  for (const double alpha : {0.0, 0.005, 1.5})
    for (const bool layered : {false, true}) {
      TabulatedNdf ndf = tabulate_ndf(Ndf::isotropic(NdfType::ggx, alpha > 0.0 ? alpha : 0.3));
      if (alpha == 0.0) std::fill(ndf.ndf.begin(), ndf.ndf.end(), 0.0), std::fill(ndf.sigma.begin(), ndf.sigma.end(), 0.0);
      const auto lobe = std::make_shared<TabulatedMicrofacet>(
          MicrofacetTables{ndf, Smith::correlated, curve, layered ? Rgb(0.2) : Rgb(0.0), layered ? Coat{0.005, 0.04} : Coat{}, layered ? 3.0 : 1.0});
      const ShadingModel model(lobe, VisibleSlopeProposal::of(*lobe));
      ASSERT_TRUE(model.lanes<TabulatedLanes>());
      // And the proposal alone (a measured table's: no f in the lanes), whose f's tables are null.
      const auto slopes = VisibleSlopeProposal::of(*lobe);  // the lanes' model points into its tables
      const TabulatedBatchModel proposal_only = TabulatedBatchModel::of(*slopes, nullptr, 0.85);
      ASSERT_FALSE(proposal_only.f);
      for (std::size_t n = 0; n <= 40; ++n)
        for (const SimdTarget target : kSimdTargets)
          for (const TabulatedBatchModel* batch_model : {&model.lanes<TabulatedLanes>()->model, &proposal_only}) {
            EvaluationBatch e;
            for (std::size_t k = 0; k < n; ++k) e.push(glm::normalize(degenerate[k % 8]), glm::normalize(degenerate[(k * 3 + 1) % 8]));
            eval_tabulated_batch(*batch_model, e, target);
            for (std::size_t k = 0; k < n; ++k) {
              for (const double v : {e.r[k], e.g[k], e.b[k], e.pdf[k]}) ASSERT_TRUE(std::isfinite(v)) << "alpha " << alpha << " pair " << k;
              if (!(e.oz[k] > 0.0 && e.iz[k] > 0.0)) {
                EXPECT_EQ(e.pdf[k], 0.0);
              }
            }
            const double ends[] = {0.0, std::nextafter(1.0, 0.0), 0.5, 1e-300, 1.0 / VisibleSlopes::kGuide};
            SampleBatch s;
            for (std::size_t k = 0; k < n; ++k) s.push(glm::normalize(degenerate[k % 8]), ends[k % 5], ends[(k * 3 + 1) % 5], ends[(k + 2) % 5]);
            sample_tabulated_batch(*batch_model, s, target);
            for (std::size_t k = 0; k < n; ++k)
              if (s.found[k] != 0.0) {
                EXPECT_GT(s.oz[k], 0.0);
                for (const double v : {s.ix[k], s.iy[k], s.iz[k]}) ASSERT_TRUE(std::isfinite(v)) << "alpha " << alpha << " sample " << k;
              }
          }
    }
}

// Directions no caller should pass (NaN, infinite, 1e300, zero) give a defined result from every material
// of a scene, never a table indexed by NaN (issue 47: the Python module crashed on them; under ASan here).
TEST(Stress, NonFiniteAndHugeDirectionsGiveZero) {
  test::TempDir dir;
  const Fitter fitter{FitOptions::paper()};
  write_lut(dir.file("gold.exr"),
            make_lut(fitter.fit(load_table("builtin:gold-ggx-0.15")), fitter.quadrature(), "builtin:gold-ggx-0.15", "x", 0.02, true));
  const SceneDesc scene = parse_scene_text(R"({"materials": {
      "merl": {"type": "measured", "file": "builtin:gold-ggx-0.15", "proposal": "gold.exr"},
      "lut": {"type": "lut", "file": "gold.exr"}, "stretched": {"type": "lut", "file": "gold.exr", "stretch": [2, 0.5], "rotation": 30},
      "closures": {"type": "closures", "file": "gold.exr"}, "ggx": {"type": "ggx", "file": "gold.exr"},
      "analytic": {"type": "analytic", "file": "builtin:gold-ggx-0.15"}},
    "objects": [{"type": "sphere", "material": "lut"}]})", dir.file("scene.json"), dir.path().string());
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const Vec3 good = glm::normalize(Vec3(0.3, 0.2, 0.9));
  const Vec3 bad[] = {Vec3(nan), Vec3(nan, 0.0, 1.0), Vec3(0.0, 0.0, inf), Vec3(0.0, inf, 1.0), Vec3(1e300, 0.0, 1e300), Vec3(0.0)};
  for (const auto& [name, desc] : scene.materials) {
    const auto model = load_material(scene, desc);
    for (const Vec3& b : bad) {
      for (const auto& [o, i] : {std::pair{good, b}, std::pair{b, good}, std::pair{b, b}}) {
        const Rgb f = model->f(o, i);
        EXPECT_TRUE(finite(f) && f.r == 0.0 && f.g == 0.0 && f.b == 0.0) << name << ": f " << f.r;
        const double pdf = model->pdf(o, i);
        EXPECT_TRUE(finite(pdf) && pdf >= 0.0) << name << ": pdf " << pdf;
      }
      const auto s = model->sample(b, 0.3, 0.6, 0.5);
      EXPECT_TRUE(!s || (finite(s->weight) && finite(s->pdf))) << name;
    }
  }
}

TEST(MerlLanes, EveryBatchLengthAndDegenerateDirectionStayFiniteAndInBounds) {
  // As above for a MERL-layout table's kernel (render/merl_batch.h): its eight gathers per channel stay
  // inside the table at every edge of its axes (the normal, the horizon, phi_d wrapping), for a table
  // whose bins are all measured and one whose bins are all missing.
  const Vec3 degenerate[] = {{0, 0, 1}, {1, 0, 0}, {0, -1, 0}, {0.6, 0, 0.8}, {-0.6, 0, -0.8}, {0, 0, -1}, {1e-300, 0, 1}, {0.9999999, 0, 1e-12}};
  for (const bool empty : {false, true}) {
    const HalfDiffTable table = empty ? HalfDiffTable() : load_table("builtin:red-plastic");
    const auto model = MerlBatchModel::of(table);
    ASSERT_TRUE(model);
    for (std::size_t n = 0; n <= 40; ++n)
      for (const SimdTarget target : kSimdTargets) {
        EvaluationBatch e;
        for (std::size_t k = 0; k < n; ++k) e.push(glm::normalize(degenerate[k % 8]), glm::normalize(degenerate[(k * 3 + 1) % 8]));
        eval_merl_batch(*model, e, target);
        for (std::size_t k = 0; k < n; ++k)
          for (const double v : {e.r[k], e.g[k], e.b[k]}) ASSERT_TRUE(std::isfinite(v)) << "pair " << k;
      }
  }
}

TEST(CameraLanes, EveryBatchLengthAndTheImageCornersGiveUnitDirections) {
  // As above for a tile's camera samples (render/camera_batch.h): any length from 0 to 40 under the
  // sanitizers, the corners of a one-pixel and of a 16384-pixel-wide image, a camera looking straight
  // down (forward along -y, the up vector's axis turned into the image's); numbers in [0, 1).
  for (const int size : {1, 16384}) {
    PinholeCamera camera;
    camera.position = Vec3(0.0, 5.0, 0.0);
    camera.forward = Vec3(0.0, -1.0, 0.0), camera.right = Vec3(1.0, 0.0, 0.0), camera.up = Vec3(0.0, 0.0, -1.0);
    camera.tan_half = std::tan(0.5 * 170.0 * kPi / 180.0), camera.aspect = 1.0;
    camera.to_sx = camera.to_sy = 2.0 / size;
    for (std::size_t n = 0; n <= 40; ++n)
      for (const SimdTarget target : kSimdTargets) {
        CameraSampleBatch b;
        for (std::size_t k = 0; k < n; ++k) b.push(k % 2 ? size - 1 : 0, k % 4 < 2 ? 0 : size - 1);
        camera_sample_batch(camera, ~std::uint64_t(0), 1 << 30, b, target);
        for (std::size_t k = 0; k < n; ++k) {
          for (const auto& u : b.u) ASSERT_TRUE(u[k] >= 0.0 && u[k] < 1.0) << "sample " << k;
          for (const double v : {b.dx[k], b.dy[k], b.dz[k]}) ASSERT_TRUE(std::isfinite(v)) << "sample " << k;
          EXPECT_NEAR(glm::length(b.d(k)), 1.0, 1e-12) << "sample " << k;
        }
      }
  }
}

}  // namespace
}  // namespace facetfit
