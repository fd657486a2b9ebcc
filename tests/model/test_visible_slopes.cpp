// The renderer's slope-space draw of a tabulated lobe's visible normals (model/visible_slopes.h): its
// density against its draws (chi-square in the space of i, as Mitsuba tests its BSDFs, with a Bonferroni
// correction over the cases), its mass, and how close it is to the lobe's true visible normals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "chi2.h"
#include "model/ndf.h"
#include "model/tabulated.h"
#include "model/visible_slopes.h"
#include "test_util.h"

namespace facetfit {
namespace {

using test::direction_at;

struct Lobe {
  NdfType type;
  double alpha;
};
constexpr Lobe kLobes[] = {{NdfType::ggx, 0.005}, {NdfType::ggx, 0.15}, {NdfType::ggx, 1.5}, {NdfType::beckmann, 0.3}};
constexpr double kViews[] = {0.0, 40.0, 75.0, 89.0};

// The normals h `drawn`, binned on the draw's own cells (view frame, v and w, y~'s sign; 4 x 4 cells a bin,
// so bins never straddle a cell's edge where the density jumps), against pdf() times the solid angle of
// each cell (of `slopes`, which also bins), which the test takes from the mapping itself: the area of the spherical quad between the
// normals at the cell's corners, 4 x 4 pieces a cell.
test::ChiSquareResult chi_square_in_slopes(const VisibleSlopes& drawn, const VisibleSlopes& slopes, const Vec3& o, int n, unsigned seed) {
  constexpr int kV = VisibleSlopes::kCells, kW = VisibleSlopes::kSideCells, kBin = 4, kSub = 4;
  constexpr int kBinsV = kV / kBin, kBinsW = kW / kBin;
  const double o_xy = std::hypot(o.x, o.y), c = o_xy > 0.0 ? o.x / o_xy : 1.0, s = o_xy > 0.0 ? o.y / o_xy : 0.0;
  const double scale = slopes.scale();
  // The normal at (v, w, sign) in the local frame.
  const auto normal = [&](double v, double w, double sign) {
    v = std::clamp(v, -VisibleSlopes::kEdge, VisibleSlopes::kEdge), w = std::min(w, VisibleSlopes::kEdge);
    const double x = scale * v / (1.0 - std::abs(v)), y = sign * scale * w / (1.0 - w);
    const Vec3 h = glm::normalize(Vec3(-x, -y, 1.0));
    return Vec3(c * h.x - s * h.y, s * h.x + c * h.y, h.z);
  };
  const std::size_t outside = std::size_t(2 * kBinsV * kBinsW);
  std::vector<double> observed(outside + 1, 0.0), expected(outside + 1, 0.0);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < n; ++k) {
    const Vec3 h = drawn.sample(o, u(rng), u(rng));
    if (glm::dot(o, h) <= 0.0) {
      observed[outside] += 1;
      continue;
    }
    const double x = -(c * h.x + s * h.y) / h.z, y = -(c * h.y - s * h.x) / h.z;
    const double v = x / (scale + std::abs(x)), w = std::abs(y) / (scale + std::abs(y));
    const int a = std::clamp(int((v + 1.0) * 0.5 * kV), 0, kV - 1) / kBin, b = std::min(int(w * kW), kW - 1) / kBin;
    observed[std::size_t(((y > 0.0 ? 1 : 0) * kBinsV + a) * kBinsW + b)] += 1;
  }
  double total = 0.0;
  for (int side = 0; side < 2; ++side)
    for (int a = 0; a < kBinsV; ++a)
      for (int b = 0; b < kBinsW; ++b) {
        double sum = 0.0;
        const double dv = 2.0 / (kV * kSub), dw = 1.0 / (kW * kSub);
        for (int p = 0; p < kBin * kSub; ++p)
          for (int q = 0; q < kBin * kSub; ++q) {
            const double v0 = -1.0 + (a * kBin * kSub + p) * dv, w0 = (b * kBin * kSub + q) * dw;
            const double sign = side ? 1.0 : -1.0;
            const Vec3 h00 = normal(v0, w0, sign), h10 = normal(v0 + dv, w0, sign), h01 = normal(v0, w0 + dw, sign),
                       h11 = normal(v0 + dv, w0 + dw, sign);
            // Two spherical triangles' areas (Van Oosterom and Strackee).
            const auto triangle = [](const Vec3& p1, const Vec3& p2, const Vec3& p3) {
              return 2.0 * std::abs(std::atan2(glm::dot(p1, glm::cross(p2, p3)),
                                               1.0 + glm::dot(p1, p2) + glm::dot(p2, p3) + glm::dot(p3, p1)));
            };
            const double area = triangle(h00, h10, h11) + triangle(h00, h11, h01);
            sum += slopes.pdf(o, normal(v0 + 0.5 * dv, w0 + 0.5 * dw, sign)) * area;
          }
        expected[std::size_t((side * kBinsV + a) * kBinsW + b)] = sum * n;
        total += sum;
      }
  expected[outside] = std::max(0.0, (1.0 - total) * n);
  return test::chi_square(observed, expected);
}

TEST(VisibleSlopes, DrawsFollowTheirDensity) {
  // 16 cases, each must pass at 1e-3 / 16 (Bonferroni): a correct sampler fails one with probability 1e-3.
  constexpr double kThreshold = 1e-3 / 16;
  for (const Lobe& lobe : kLobes) {
    const VisibleSlopes slopes(tabulate_ndf(Ndf::isotropic(lobe.type, lobe.alpha)));
    for (const double theta_o : kViews) {
      SCOPED_TRACE(std::to_string(lobe.alpha) + " at " + std::to_string(theta_o));
      const test::ChiSquareResult r = chi_square_in_slopes(slopes, slopes, direction_at(theta_o), 300000, 5);
      EXPECT_GT(r.p_value, kThreshold) << "chi2 " << r.statistic << " dof " << r.dof;
    }
  }
}

TEST(VisibleSlopes, DirectionsFollowTheProposalsDensity) {
  // The proposal's directions i (reflection, the body's cosine and the coat's GGX) against its pdf in the
  // space of i, where the harness's midpoint quadrature resolves a rough lobe: 6 cases at 1e-3 / 6.
  for (const double alpha : {0.15, 0.5}) {
    const ProposalParts parts(Rgb(0.5), Rgb(0.4, 0.2, 0.1), alpha > 0.3 ? Coat{0.25, 0.05} : Coat{});
    const VisibleSlopeProposal proposal(tabulate_ndf(Ndf::isotropic(NdfType::ggx, alpha)), parts);
    for (const double theta_o : {0.0, 40.0, 75.0}) {
      SCOPED_TRACE(std::to_string(alpha) + " at " + std::to_string(theta_o));
      const Vec3 o = direction_at(theta_o);
      const test::ChiSquareResult r = test::chi_square_in_directions(
          [&](double u1, double u2) { return proposal.sample_direction(o, u1, u2); }, [&](const Vec3& i) { return proposal.pdf(o, i); },
          300000, 7);
      EXPECT_GT(r.p_value, 1e-3 / 6) << "chi2 " << r.statistic << " dof " << r.dof;
    }
  }
}

TEST(VisibleSlopes, ChiSquareRejectsTheDensityOfARougherLobe) {
  // Negative control: draws of GGX 0.30 against the density built for GGX 0.33.
  const VisibleSlopeProposal drawn(tabulate_ndf(Ndf::isotropic(NdfType::ggx, 0.30)), ProposalParts{});
  const VisibleSlopeProposal other(tabulate_ndf(Ndf::isotropic(NdfType::ggx, 0.33)), ProposalParts{});
  const Vec3 o = direction_at(40.0);
  const test::ChiSquareResult r = test::chi_square_in_directions([&](double u1, double u2) { return drawn.sample_direction(o, u1, u2); },
                                                                 [&](const Vec3& i) { return other.pdf(o, i); }, 200000, 5);
  EXPECT_LT(r.p_value, 1e-6);
  // And in slope space, bins on the rougher lobe's cells.
  EXPECT_LT(chi_square_in_slopes(drawn.slopes(), other.slopes(), o, 300000, 5).p_value, 1e-6);
}

TEST(VisibleSlopes, DensityOfTheNormalsIntegratesToTheVisibleShareAndMatchesTheLobes) {
  // Over the hemisphere of h: the density integrates to the share of draws that face o (1 but for the
  // cell the view's horizon cuts), and it is the lobe's visible normals D_o(h) = G1(o) max(0, o.h) D(h) /
  // cos(theta_o) to within the cells' resolution: the L1 distance of the two densities.
  for (const Lobe& lobe : kLobes) {
    const Ndf ndf = Ndf::isotropic(lobe.type, lobe.alpha);
    const VisibleSlopes slopes(tabulate_ndf(ndf));
    for (const double theta_o : kViews) {
      SCOPED_TRACE(std::to_string(lobe.alpha) + " at " + std::to_string(theta_o));
      const Vec3 o = direction_at(theta_o);
      // Draws: the share facing o.
      std::mt19937 rng(3);
      std::uniform_real_distribution<double> u(0.0, 1.0);
      int facing = 0;
      constexpr int kDraws = 100000;
      for (int k = 0; k < kDraws; ++k) {
        const Vec3 h = slopes.sample(o, u(rng), u(rng));
        ASSERT_TRUE(std::isfinite(h.x + h.y + h.z));
        ASSERT_NEAR(glm::length(h), 1.0, 1e-12);
        facing += glm::dot(o, h) > 0.0;
      }
      // Integrals over h in (theta_h, phi_h), theta_h on u^2 (the lobe's peak is narrow).
      constexpr int kTheta = 2000, kPhi = 720;
      const double g1_o = 1.0 / (1.0 + ndf.lambda(o));
      double mass = 0.0, distance = 0.0;
      for (int a = 0; a < kTheta; ++a) {
        const double uu = (a + 0.5) / kTheta, theta = uu * uu * 0.5 * kPi, dtheta = uu * kPi / kTheta;
        for (int b = 0; b < kPhi; ++b) {
          const Vec3 h = spherical_direction(theta, (b + 0.5) / kPhi * 2.0 * kPi);
          const double d_omega = std::sin(theta) * dtheta * (2.0 * kPi / kPhi);
          const double p = slopes.pdf(o, h), truth = g1_o * std::max(0.0, glm::dot(o, h)) * ndf.D(h) / o.z;
          ASSERT_TRUE(std::isfinite(p) && p >= 0.0);
          mass += p * d_omega;
          distance += std::abs(p - truth) * d_omega;
        }
      }
      EXPECT_NEAR(mass, double(facing) / kDraws, 0.01);
      EXPECT_GT(mass, 0.97);
      EXPECT_LT(distance, 0.05);
    }
  }
}

// Every row's guide (core/piecewise_constant.h, append_cdf_guide) brackets the cell that inverting the row
// draws (the last whose running sum is <= u), and its masses are its sums' steps: for a peak narrower than
// the cells (alpha 0.005: rows with long runs of empty cells, where the guide's steps are widest), a broad
// lobe and an NDF that is zero (uniform rows).
TEST(VisibleSlopes, GuidesBracketEveryDraw) {
  constexpr int guide = VisibleSlopes::kGuide;
  for (const double alpha : {0.0, 0.005, 0.3, 1.5}) {
    TabulatedNdf ndf = tabulate_ndf(Ndf::isotropic(NdfType::ggx, alpha > 0.0 ? alpha : 0.3));
    if (alpha == 0.0) std::fill(ndf.ndf.begin(), ndf.ndf.end(), 0.0);
    const VisibleSlopes slopes(ndf);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    const auto check = [&](const std::vector<double>& cdfs, const std::vector<double>& masses, const std::vector<std::int64_t>& guides,
                           int rows, int n) {
      ASSERT_EQ(cdfs.size(), std::size_t(rows) * (n + 1));
      ASSERT_EQ(masses.size(), std::size_t(rows) * n);
      ASSERT_EQ(guides.size(), std::size_t(rows) * (guide + 1));
      for (int row = 0; row < rows; ++row) {
        const double* cdf = cdfs.data() + std::size_t(row) * (n + 1);
        ASSERT_EQ(cdf[0], 0.0);
        ASSERT_EQ(cdf[n], 1.0);
        for (int k = 0; k < n; ++k) ASSERT_NEAR(cdf[k + 1] - cdf[k], masses[std::size_t(row) * n + k], 1e-15);
        for (int m = 0; m < 100; ++m) {
          // Also a u on a guide entry, the last below 1, and one on a cell's sum.
          const double u = m < 2 ? double(m) / guide : m == 2 ? std::nextafter(1.0, 0.0) : m == 3 ? cdf[n / 2] : m == 4 ? cdf[n - 1] : uniform(rng);
          const int cell = int(std::upper_bound(cdf, cdf + n + 1, u) - cdf) - 1;
          const std::int64_t* entry = guides.data() + std::size_t(row) * (guide + 1) + std::min(int(u * guide), guide - 1);
          EXPECT_LE(entry[0], cell) << alpha << " row " << row << " u " << u;
          EXPECT_GE(entry[1], cell) << alpha << " row " << row << " u " << u;
        }
      }
    };
    check(slopes.view_cdf(), slopes.view_mass(), slopes.view_guide(), VisibleSlopes::kSlices, VisibleSlopes::kCells);
    check(slopes.side_cdf(), slopes.side_mass(), slopes.side_guide(), VisibleSlopes::kCells, VisibleSlopes::kSideCells);
  }
}

}  // namespace
}  // namespace facetfit
