// The tabulated model: evaluation against the analytic truth, reciprocity, energy, and sampling
// against its pdf (chi-square, as Mitsuba tests its BSDFs).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include "chi2.h"
#include "fit/fit.h"
#include "fit/quadrature.h"
#include "model/analytic.h"
#include "model/tabulated.h"
#include "model/visible_azimuth.h"
#include "test_util.h"

namespace facetfit {
namespace {

MicrofacetTables fitted_tables(NdfType type, double alpha, const Fresnel& fresnel, Smith smith = Smith::correlated) {
  FitOptions options = FitOptions::paper();
  options.smith = smith;
  const FitResult fit = Fitter(options).fit(HalfDiffTable::tabulate(MicrofacetBrdf(Ndf::isotropic(type, alpha), smith, fresnel)));
  EXPECT_TRUE(fit.ok()) << fit.problem;
  return {fit.ndf(), smith, fit.fresnel(), {}, {}};
}

using test::direction_at;

TEST(Tabulated, EvalMatchesTheAnalyticModel) {
  const Fresnel gold = Fresnel::conductor({0.143, 0.374, 1.442}, {3.983, 2.385, 1.603});
  for (double alpha : {0.1, 0.5}) {
    const MicrofacetBrdf truth(Ndf::isotropic(NdfType::ggx, alpha), Smith::correlated, gold);
    const TabulatedMicrofacet model(fitted_tables(NdfType::ggx, alpha, gold));
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int n = 0; n < 500; ++n) {
      const Vec3 i = spherical_direction(std::acos(u(rng)) * 0.95, 2 * kPi * u(rng));
      const Vec3 o = spherical_direction(std::acos(u(rng)) * 0.95, 2 * kPi * u(rng));
      const Rgb a = *truth.eval(o, i), b = *model.eval(o, i);
      if (luminance(a) < 1e-3) continue;
      EXPECT_NEAR(b.g / a.g, 1.0, 0.01) << "alpha " << alpha << " i " << i.z << " o " << o.z;
    }
  }
}

TEST(Tabulated, Reciprocal) {
  const TabulatedMicrofacet model(fitted_tables(NdfType::beckmann, 0.3, Fresnel::schlick(Rgb(0.9, 0.5, 0.2))));
  std::mt19937 rng(4);
  for (int n = 0; n < 200; ++n) {
    const Vec3 i = test::random_direction(rng), o = test::random_direction(rng);
    const Rgb a = *model.eval(o, i), b = *model.eval(i, o);
    EXPECT_NEAR(a.r, b.r, 1e-12 * std::max(1.0, a.r));
  }
}

// Integral of pdf(o, .) over the upper hemisphere, by midpoint quadrature in (cos theta, phi),
// refined near the specular peak by the fine grid.
double pdf_integral(const TabulatedMicrofacet& model, const Vec3& o, int n_cos = 800, int n_phi = 800) {
  double sum = 0.0;
  for (int a = 0; a < n_cos; ++a) {
    const double c = (a + 0.5) / n_cos, s = std::sqrt(1.0 - c * c);
    for (int b = 0; b < n_phi; ++b) {
      const double phi = (b + 0.5) * 2 * kPi / n_phi;
      sum += model.pdf(o, Vec3(s * std::cos(phi), s * std::sin(phi), c));
    }
  }
  return sum * (1.0 / n_cos) * (2 * kPi / n_phi);
}

class Sampling : public testing::TestWithParam<std::tuple<double, double>> {};

// n samples of `model` seen from o, counted in `bins` bins by bin_of(i) (-1: in none); the last entry of
// the result (index `bins`) counts the samples in no bin and the draws that returned nothing.
std::vector<double> sample_histogram(const TabulatedMicrofacet& model, const Vec3& o, int n, unsigned seed, std::size_t bins,
                                     const std::function<int(const Vec3&)>& bin_of) {
  std::vector<double> observed(bins + 1, 0.0);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < n; ++k) {
    const auto s = model.sample(o, u(rng), u(rng));
    const int bin = s ? bin_of(s->i) : -1;
    observed[bin < 0 ? bins : std::size_t(bin)] += 1;
  }
  return observed;
}

// Integral of the visible-normal density over the half vectors whose reflection of o is above the
// horizon: the same quantity as the integral of pdf(o, .) over i, computed where even a sharp lobe is
// wide, on bins aligned with the model's grid (the density is constant in cos(theta) inside them).
double reflected_mass_in_h(const TabulatedMicrofacet& model, const Vec3& o) {
  const ThetaGrid& grid = model.tables().ndf.grid;
  constexpr int kSub = 16, kPhi = 256;
  double sum = 0.0;
  for (int j = 0; j < grid.resolution; ++j) {
    const double c0 = std::cos(grid.theta(j)), c1 = std::cos(grid.theta(j + 1)), dc = (c0 - c1) / kSub;
    for (int p = 0; p < kSub; ++p) {
      const double c = c0 - (p + 0.5) * dc, sn = std::sqrt(1 - c * c);
      for (int q = 0; q < kPhi; ++q) {
        const double phi = (q + 0.5) * 2 * kPi / kPhi;
        const Vec3 h(sn * std::cos(phi), sn * std::sin(phi), c);
        if ((2.0 * glm::dot(o, h) * h - o).z > 0.0) sum += model.visible_normal_pdf(o, h) * dc * 2 * kPi / kPhi;
      }
    }
  }
  return sum;
}

TEST_P(Sampling, PdfIntegratesToTheSampledMass) {
  const auto [alpha, theta_o] = GetParam();
  const TabulatedMicrofacet model(fitted_tables(NdfType::ggx, alpha, Fresnel::one()));
  const Vec3 o = direction_at(theta_o);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int n = 200000;
  int valid = 0;
  for (int k = 0; k < n; ++k) valid += model.sample(o, u(rng), u(rng)).has_value();
  const double mass = double(valid) / n;
  EXPECT_NEAR(reflected_mass_in_h(model, o), mass, 0.005);
  // In the space of i itself, where midpoint quadrature resolves a rough lobe.
  if (alpha >= 0.1) {
    EXPECT_NEAR(pdf_integral(model, o), mass, 0.01);
  }
}

TEST_P(Sampling, ChiSquareAgainstPdf) {
  const auto [alpha, theta_o] = GetParam();
  const TabulatedMicrofacet model(fitted_tables(NdfType::ggx, alpha, Fresnel::one()));
  const Vec3 o = direction_at(theta_o);
  // Histogram of the half vectors (where even a sharp lobe is spread over many bins). The theta_h bins
  // halve each interval of the model's grid in cos(theta): the sampler's density jumps at grid nodes, so
  // bins that straddled them would need an exact integral of a discontinuous function; halving still
  // tests how samples are placed inside an interval.
  const ThetaGrid& grid = model.tables().ndf.grid;
  const double theta_max = std::min(0.5 * kPi, 8.0 * alpha + 0.05);
  std::vector<double> edges{1.0};  // cos(theta) edges, decreasing
  for (int j = 0; j < grid.resolution && grid.theta(j) < theta_max; ++j) {
    const double c0 = std::cos(grid.theta(j)), c1 = std::cos(grid.theta(j + 1));
    edges.push_back(0.5 * (c0 + c1));
    edges.push_back(c1);
  }
  const int n_theta = int(edges.size()) - 1;
  constexpr int kPhi = 48, kSub = 8;
  const auto bin_of = [&](const Vec3& h) {
    const int a = int(std::upper_bound(edges.begin(), edges.end(), h.z, std::greater<double>()) - edges.begin()) - 1;
    if (a < 0 || a >= n_theta) return -1;
    double phi = std::atan2(h.y, h.x);
    if (phi < 0) phi += 2 * kPi;
    return a * kPhi + std::min(kPhi - 1, int(phi / (2 * kPi) * kPhi));
  };
  const std::size_t outside = std::size_t(n_theta) * kPhi;
  const int n = 400000;
  std::vector<double> observed =
      sample_histogram(model, o, n, 6, outside, [&](const Vec3& i) { return bin_of(glm::normalize(i + o)); });
  std::vector<double> expected(outside + 1, 0.0);
  // Expected: n times the integral over the bin of the visible-normal density (per steradian of h) of
  // the samples whose reflection is above the horizon; d(omega) = d(cos theta) d(phi).
  // Bins that the horizon of the reflected direction (i.z = 0) cuts through are integrated 16x finer.
  const auto bin_integral = [&](int a, int b, int sub, bool* cut) {
    double sum = 0.0;
    bool above = false, below = false;
    const double dc = (edges[std::size_t(a)] - edges[std::size_t(a) + 1]) / sub, dphi = 2 * kPi / (kPhi * sub);
    for (int p = 0; p < sub; ++p)
      for (int q = 0; q < sub; ++q) {
        const double c = edges[std::size_t(a)] - (p + 0.5) * dc, sn = std::sqrt(1 - c * c);
        const double phi = (b * sub + q + 0.5) * dphi;
        const Vec3 h(sn * std::cos(phi), sn * std::sin(phi), c);
        const Vec3 i = 2.0 * glm::dot(o, h) * h - o;
        (i.z > 0.0 ? above : below) = true;
        if (i.z > 0.0) sum += model.visible_normal_pdf(o, h) * dc * dphi;
      }
    if (cut) *cut = above && below;
    return sum;
  };
  double total = 0.0;
  for (int a = 0; a < n_theta; ++a)
    for (int b = 0; b < kPhi; ++b) {
      bool cut = false;
      double sum = bin_integral(a, b, kSub, &cut);
      if (cut) sum = bin_integral(a, b, 16 * kSub, nullptr);
      expected[std::size_t(a * kPhi + b)] = sum * n;
      total += sum;
    }
  // The last category holds every sample not in a bin: reflected below the horizon (sample() returns
  // nothing) or beyond theta_max. Its expectation follows from n, since the visible normals integrate to one.
  expected[outside] = std::max(0.0, (1.0 - total) * n);
  const test::ChiSquareResult r = test::chi_square(observed, expected);
  EXPECT_GT(r.p_value, 1e-3) << "chi2 " << r.statistic << " dof " << r.dof;
}

INSTANTIATE_TEST_SUITE_P(Incidence, Sampling,
                         testing::Combine(testing::Values(0.05, 0.5), testing::Values(0.0, 30.0, 60.0, 85.0)));

// The mixture of a model with a body and a coat (lobe, cosine, GGX visible normals), in the space of i:
// the samples against pdf(), bins uniform in cos(theta_i) and phi_i, integrated 8 x 8 finer.
TEST(Sampling, ChiSquareOfTheBodyLobeCoatMixture) {
  MicrofacetTables tables = fitted_tables(NdfType::ggx, 0.5, Fresnel::schlick(Rgb(0.04)));
  tables.body = Rgb(0.4, 0.2, 0.1);
  tables.coat = Coat{0.25, 0.05};
  const TabulatedMicrofacet model(tables);
  ASSERT_GT(model.body_weight(), 0.3);
  ASSERT_GT(model.coat_weight(), 0.1);
  for (const double theta_o : {0.0, 40.0, 75.0}) {
    SCOPED_TRACE(theta_o);
    const Vec3 o = direction_at(theta_o);
    const test::ChiSquareResult r = test::chi_square_in_directions(
        [&](double u1, double u2) { return model.sample_direction(o, u1, u2); }, [&](const Vec3& i) { return model.pdf(o, i); }, 300000, 9);
    EXPECT_GT(r.p_value, 1e-3) << "chi2 " << r.statistic << " dof " << r.dof;
  }
}

TEST(Sampling, ChiSquareRejectsAWrongPdf) {
  // Negative control: samples of one material against the pdf of a 10% rougher one must fail.
  const TabulatedMicrofacet sampler(fitted_tables(NdfType::ggx, 0.30, Fresnel::one()));
  const TabulatedMicrofacet other(fitted_tables(NdfType::ggx, 0.33, Fresnel::one()));
  const Vec3 o = direction_at(40.0);
  constexpr int kBins = 40;
  std::vector<double> observed(kBins, 0.0), expected(kBins, 0.0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int n = 100000;
  for (int k = 0; k < n; ++k)
    if (const auto s = sampler.sample(o, u(rng), u(rng))) observed[std::size_t(std::min(kBins - 1, int(s->i.z * kBins)))] += 1;
  for (int a = 0; a < kBins; ++a)
    for (int p = 0; p < 50; ++p)
      for (int q = 0; q < 400; ++q) {
        const double c = (a + (p + 0.5) / 50) / kBins, s = std::sqrt(1 - c * c), phi = (q + 0.5) / 400 * 2 * kPi;
        expected[std::size_t(a)] += other.pdf(o, Vec3(s * std::cos(phi), s * std::sin(phi), c)) * n / (kBins * 50) * (2 * kPi / 400);
      }
  EXPECT_LT(test::chi_square(observed, expected).p_value, 1e-6);
}

TEST(Tabulated, MinnaertBodyKeepsItsAlbedoAtNormalIncidence) {
  // A body alone (the lobe's Fresnel curve zero) with Minnaert's exponent k (model/body.h): its directional
  // albedo is body cos(theta_o)^(k - 1), by a deterministic integral and by the sampler's estimate (the
  // body is drawn by the cosine, its weight f cos / pdf).
  MicrofacetTables tables = fitted_tables(NdfType::ggx, 0.3, Fresnel::one());
  for (auto& v : tables.fresnel.value) v = Rgb(0.0);
  tables.body = Rgb(0.5);
  for (const double k : {1.0, 1.5, 3.0}) {
    tables.body_exponent = k;
    const TabulatedMicrofacet model(tables);
    for (const double theta_o : {0.0, 60.0, 80.0}) {
      const Vec3 o = direction_at(theta_o);
      const double expected = 0.5 * std::pow(o.z, k - 1.0);
      double integral = 0.0;
      const int m = 2000;
      for (int a = 0; a < m; ++a) {  // isotropic in phi: one azimuth, 2 pi
        const double c = (a + 0.5) / m;
        integral += model.eval(o, Vec3(std::sqrt(1 - c * c), 0.0, c))->g * c / m * 2 * kPi;
      }
      EXPECT_NEAR(integral, expected, 1e-3 * expected) << "k " << k << " theta_o " << theta_o;
      std::mt19937 rng(3);
      std::uniform_real_distribution<double> u(0.0, 1.0);
      double estimate = 0.0;
      const int n = 40000;
      for (int s = 0; s < n; ++s)
        if (const auto drawn = model.sample(o, u(rng), u(rng))) estimate += drawn->weight.g / n;
      EXPECT_NEAR(estimate, expected, 0.02 * expected) << "k " << k << " theta_o " << theta_o;
    }
  }
}

TEST(Tabulated, WhiteFurnace) {
  // F = 1: the albedo is at most 1 (single scattering loses energy to masking), and the sampler's
  // estimate agrees with a deterministic integral of the model.
  for (double alpha : {0.05, 0.5, 1.0}) {
    const TabulatedMicrofacet model(fitted_tables(NdfType::ggx, alpha, Fresnel::one()));
    for (double theta_o : {0.0, 60.0, 85.0}) {
      const Vec3 o = direction_at(theta_o);
      std::mt19937 rng(8);
      std::uniform_real_distribution<double> u(0.0, 1.0);
      const int n = 100000;
      double albedo = 0.0, max_weight = 0.0;  // F = 1
      for (int k = 0; k < n; ++k)
        if (const auto s = model.sample(o, u(rng), u(rng))) {
          albedo += s->weight.g / n;
          max_weight = std::max(max_weight, s->weight.g);
        }
      EXPECT_LE(albedo, 1.0 + 3e-3) << "alpha " << alpha << " theta_o " << theta_o;
      // An exact visible-normal sampler gives weights F G2 / G1 <= 1; ours matches the visible normals per
      // grid interval, so weights stay near 1 (low variance) without being bounded by it exactly.
      EXPECT_LE(max_weight, 1.25) << "alpha " << alpha << " theta_o " << theta_o;
      EXPECT_GT(albedo, 0.25);
      if (alpha >= 0.5) {  // the quadrature resolves rough lobes: compare
        double integral = 0.0;
        const int m = 600;
        for (int a = 0; a < m; ++a)
          for (int b = 0; b < m; ++b) {
            const double c = (a + 0.5) / m, s = std::sqrt(1 - c * c), phi = (b + 0.5) / m * 2 * kPi;
            integral += model.eval(o, Vec3(s * std::cos(phi), s * std::sin(phi), c))->g * c / (m * m) * 2 * kPi;
          }
        EXPECT_NEAR(albedo, integral, 5e-3) << "alpha " << alpha << " theta_o " << theta_o;
      }
    }
  }
}

TEST(Tabulated, ExtremesStayFinite) {
  for (double alpha : {0.005, 1.5}) {
    const TabulatedMicrofacet model(fitted_tables(NdfType::ggx, alpha, Fresnel::one()));
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (double theta_o : {0.0, 45.0, 89.0, 89.99}) {
      const Vec3 o = direction_at(theta_o);
      for (int k = 0; k < 2000; ++k) {
        const auto s = model.sample(o, u(rng), u(rng));
        if (!s) continue;
        ASSERT_TRUE(std::isfinite(s->pdf) && s->pdf > 0.0);
        ASSERT_TRUE(std::isfinite(s->weight.r) && s->weight.r >= 0.0);
      }
    }
  }
}

// The density per cos(theta_h) that pdf() reads is each interval's mass over its band: for a peak narrower
// than a node (alpha 0.005, where most intervals hold no mass) and a broad lobe.
TEST(Tabulated, VisibleDensityIsMassOverBand) {
  for (double alpha : {0.005, 0.3, 1.5}) {
    const TabulatedMicrofacet model(fitted_tables(NdfType::ggx, alpha, Fresnel::one()));
    const VisibleNormalTables& tables = model.sampling();
    const int r = tables.resolution;
    ASSERT_EQ(model.visible_density().size(), std::size_t(r + 1) * r);
    for (int s = 0; s <= r; ++s)
      for (int j = 0; j < r; ++j) {
        const double band = model.cos_nodes()[std::size_t(j)] - model.cos_nodes()[std::size_t(j) + 1];
        EXPECT_NEAR(model.visible_density()[std::size_t(s) * r + j] * band, tables.mass(s, j), 1e-15) << alpha << " " << s << " " << j;
      }
  }
}

// The azimuth's CDF a sin(phi) + b phi on [0, phi_max], written out here independently of
// model/visible_azimuth.cpp, and its root for a target by bisection to the last bit.
struct AzimuthCdf {
  double a, b, phi_max, total;
  AzimuthCdf(double a_, double b_) : a(a_), b(b_), phi_max(a_ <= b_ ? kPi : std::acos(-b_ / a_)), total(at(phi_max)) {}
  double at(double phi) const { return a * std::sin(phi) + b * phi; }
  double root(double target) const {
    double lo = 0.0, hi = phi_max;
    for (int it = 0; it < 64; ++it) {
      const double mid = 0.5 * (lo + hi);
      (at(mid) > target ? hi : lo) = mid;
    }
    return 0.5 * (lo + hi);
  }
};

TEST(VisibleAzimuth, InvertsItsCdf) {
  // The drawn phi is within 1e-7 radians (the sampler's stop, below what a float ray direction resolves)
  // of the root of a sin(phi) + b phi = u' total (u' = u folded onto one side, the root found by
  // bisection), wherever the table's guess starts it: both cases (a <= b, a > b), their boundary, either
  // term alone, u at the ends and at the guess's nodes.
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<std::pair<double, double>> cases = {{0.0, 1.0}, {1.0, 0.0}, {0.5, 0.5}, {0.5, 0.5 - 1e-15}, {1e-300, 1.0}, {1.0, 1e-300}};
  for (int k = 0; k < 2000; ++k) cases.emplace_back(uniform(rng), uniform(rng));
  std::vector<double> us = {0.0, 1e-17, 0.25, 0.5, 0.5 + 1e-16, 0.75, 1.0 - 1e-16};
  for (int j = 0; j <= AzimuthGuess::kSize; ++j) us.push_back(0.5 + 0.5 * j / AzimuthGuess::kSize * (1.0 - 1e-16));
  for (int k = 0; k < 20; ++k) us.push_back(uniform(rng));
  double worst = 0.0;
  for (const auto& [a, b] : cases) {
    const AzimuthCdf cdf(a, b);
    for (double u : us) {
      const auto [c, s] = sample_visible_azimuth(a, b, u);
      ASSERT_TRUE(std::isfinite(c) && std::isfinite(s)) << a << " " << b << " " << u;
      ASSERT_NEAR(c * c + s * s, 1.0, 1e-12);
      const double phi = std::atan2(std::abs(s), c), target = (u < 0.5 ? 2.0 * u : 2.0 * u - 1.0) * cdf.total;
      // Where the density vanishes (phi_max, a > b or a = b) the root itself is set only to the CDF's
      // rounding: there the CDF's value is the measure.
      const double phi_error = std::abs(phi - cdf.root(target)), cdf_error = std::abs(cdf.at(phi) - target) / cdf.total;
      EXPECT_TRUE(phi_error < 1e-7 || cdf_error < 1e-14) << a << " " << b << " " << u << ": " << phi_error << " " << cdf_error;
      worst = std::max(worst, std::min(phi_error, cdf_error));
      if (phi > 1e-7) {
        EXPECT_EQ(s < 0.0, u < 0.5) << a << " " << b << " " << u;
      }
    }
  }
  std::printf("[ azimuth ] worst of min(phi error in radians, CDF error over the total) %.1e\n", worst);
}

TEST(VisibleAzimuth, GuessIsNearTheRoot) {
  // The table's bilinear guess (what Newton starts from) at random (a, b, u): within 1e-3 radians of the
  // root for half of them and 0.1 for 99%, and inside [0, phi_max] always (a transposed table, a wrong
  // stride or an extrapolation past s = 1 would not be).
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const AzimuthGuess& guess = AzimuthGuess::table();
  std::vector<double> errors;
  for (int k = 0; k < 20000; ++k) {
    const double a = uniform(rng), b = uniform(rng), u = uniform(rng);
    const AzimuthCdf cdf(a, b);
    const double g = guess(a, b, u, cdf.phi_max);
    ASSERT_TRUE(g >= 0.0 && g <= cdf.phi_max) << a << " " << b << " " << u;
    errors.push_back(std::abs(g - cdf.root(u * cdf.total)));
  }
  std::sort(errors.begin(), errors.end());
  const double median = errors[errors.size() / 2], p99 = errors[errors.size() * 99 / 100];
  EXPECT_LT(median, 1e-3);
  EXPECT_LT(p99, 0.1);
  std::printf("[ azimuth guess ] median error %.1e, 99th percentile %.1e radians\n", median, p99);
}

TEST(VisibleAzimuth, GuessTableIsAnInverseCdf) {
  // Each row of s runs from 0 to 1, increasing, and solves its CDF at its nodes to double rounding.
  const AzimuthGuess& guess = AzimuthGuess::table();
  for (int i = 0; i <= AzimuthGuess::kSize; ++i) {
    const AzimuthCdf cdf(double(i) / AzimuthGuess::kSize, 1.0 - double(i) / AzimuthGuess::kSize);
    const double* row = guess.values() + i * AzimuthGuess::kStride;
    EXPECT_NEAR(row[0], 0.0, 1e-15);
    EXPECT_NEAR(row[AzimuthGuess::kSize], 1.0, 1e-15);
    for (int j = 0; j <= AzimuthGuess::kSize; ++j) {
      if (j > 0) {
        EXPECT_GT(row[j], row[j - 1]) << i << " " << j;
      }
      EXPECT_NEAR(cdf.at(row[j] * cdf.phi_max), double(j) / AzimuthGuess::kSize * cdf.total, 1e-14) << i << " " << j;
    }
  }
}

TEST(G1Table, FollowsTheSplineToTheHorizon) {
  // Relative error, since the fits divide G1 by cos(theta): at the horizon an absolute error would be
  // a large relative one (a table of G1 itself, uniform in cos(theta), was 2e-2 off at alpha 0.005).
  for (NdfType type : {NdfType::ggx, NdfType::beckmann})
    for (double alpha : {0.005, 0.02, 0.1, 0.3, 0.7, 1.5}) {
      const TabulatedNdf ndf = tabulate_ndf(Ndf::isotropic(type, alpha));
      const G1Table table(ndf);
      double worst = 0.0;
      for (int k = 1; k <= 200000; ++k) {
        const double c = std::pow(k / 200000.0, 3);  // down to 1.25e-16
        worst = std::max(worst, std::abs(table(c) / ndf.g1(c) - 1.0));
      }
      EXPECT_LT(worst, 1e-4) << to_string(type) << " alpha " << alpha;
    }
  const G1Table table(tabulate_ndf(Ndf::isotropic(NdfType::ggx, 0.3)));
  EXPECT_EQ(table(0.0), 0.0);
  EXPECT_EQ(table(-0.5), 0.0);
  EXPECT_EQ(table(1.0), 1.0);
}

}  // namespace
}  // namespace facetfit
