// The closure representation (model/closures.h, fit/closure_fit.h): its BRDF against the library's own
// lobes, its proposal by chi-square with a negative control, the fit's derivatives and albedo sum, and a
// known mixture written in MERL coming back.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "chi2.h"
#include "fit/closure_fit.h"
#include "fit/fit.h"
#include "fit/visible_moments.h"
#include "io/input.h"
#include "model/analytic.h"
#include "model/closures.h"
#include "model/parametric.h"
#include "model/rotated.h"
#include "test_util.h"

namespace facetfit {
namespace {

using test::TempDir;

// body + a sharp F82-tint GGX lobe of weight 0.6 + a broad generalized-Schlick one: what the fit's lobes are.
Closures two_lobes() {
  Closures c;
  c.body = Rgb(0.10, 0.15, 0.20);
  ClosureLobe sharp;
  sharp.alpha_x = sharp.alpha_y = 0.08;
  sharp.weight = 0.6;
  sharp.f0 = Rgb(0.9, 0.7, 0.5);
  sharp.f82 = Rgb(0.8, 0.65, 0.5);
  ClosureLobe broad;
  broad.alpha_x = broad.alpha_y = 0.35;
  broad.fresnel = ClosureLobe::Fresnel::schlick;
  broad.f0 = Rgb(0.05, 0.1, 0.2);
  broad.f90 = Rgb(0.6);
  broad.exponent = 5.0;
  c.lobes = {sharp, broad};
  return c;
}

std::vector<std::pair<Vec3, Vec3>> direction_pairs(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<std::pair<Vec3, Vec3>> pairs;
  for (int k = 0; k < n; ++k) pairs.emplace_back(test::random_direction(rng), test::random_direction(rng));
  return pairs;
}

TEST(Closures, EachLobeIsTheLibrarysOwn) {
  // An F82-tint lobe of weight w is w times ParametricBrdf's lobe (height-correlated Smith); a Schlick lobe
  // of exponent 5 and f90 = 1 is Schlick's; the body and the coat add as they do there.
  Closures c;
  c.body = Rgb(0.2, 0.1, 0.05);
  c.coat = Coat{0.05, 0.04};
  ClosureLobe l;
  l.alpha_x = l.alpha_y = 0.3;
  l.weight = 0.7;
  l.f0 = Rgb(0.9, 0.5, 0.2);
  l.f82 = Rgb(0.7, 0.6, 0.5);
  c.lobes = {l};
  const ParametricBrdf lobe(Ndf::isotropic(NdfType::ggx, 0.3), Smith::correlated, l.f0, l.f82);
  ClosureLobe schlick = l;
  schlick.fresnel = ClosureLobe::Fresnel::schlick;
  schlick.f90 = Rgb(1.0);
  schlick.exponent = 5.0;
  schlick.weight = 1.0;
  Closures s;
  s.lobes = {schlick};
  const MicrofacetBrdf schlick_lobe(Ndf::isotropic(NdfType::ggx, 0.3), Smith::correlated, Fresnel::schlick(l.f0));
  for (const auto& [o, i] : direction_pairs(200, 3)) {
    const Rgb want = 0.7 * *lobe.eval(o, i) + c.body * kInvPi + Rgb(c.coat.eval(o, i)), got = *ClosureBrdf(c).eval(o, i);
    const Rgb want_s = *schlick_lobe.eval(o, i), got_s = *ClosureBrdf(s).eval(o, i);
    for (int e = 0; e < 3; ++e) {
      EXPECT_NEAR(got[e], want[e], 1e-12 * std::max(1.0, want[e]));
      EXPECT_NEAR(got_s[e], want_s[e], 1e-12 * std::max(1.0, want_s[e]));
    }
  }
  // An anisotropic lobe turned by its angle is the axis-aligned one in turned coordinates.
  ClosureLobe a = l;
  a.alpha_x = 0.5, a.alpha_y = 0.1, a.angle = 0.6;
  Closures an;
  an.lobes = {a};
  const RotatedBrdf turned(std::make_shared<ParametricBrdf>(Ndf{NdfType::ggx, 0.5, 0.1}, Smith::correlated, l.f0, l.f82), 0.6);
  for (const auto& [o, i] : direction_pairs(200, 4)) {
    const Rgb want = 0.7 * *turned.eval(o, i), got = *ClosureBrdf(an).eval(o, i);
    for (int e = 0; e < 3; ++e) EXPECT_NEAR(got[e], want[e], 1e-12 * std::max(1.0, want[e]));
  }
  // The artist's scales multiply each lobe's alphas along its axes; the rotation adds to its angle.
  const Closures stretched = an.stretched(2.0, 0.5, 0.3);
  EXPECT_DOUBLE_EQ(stretched.lobes[0].alpha_x, 1.0);
  EXPECT_DOUBLE_EQ(stretched.lobes[0].alpha_y, 0.05);
  EXPECT_DOUBLE_EQ(stretched.lobes[0].angle, 0.9);
}

TEST(Closures, ProposalSamplesItsDensity) {
  // Lobes no sharper than the test's bins resolve (32 in cos theta: the top one spans 14 degrees).
  Closures c = two_lobes();
  c.coat = Coat{0.15, 0.05};
  c.lobes[0].alpha_x = c.lobes[0].alpha_y = 0.25;
  c.lobes[1].alpha_x = 0.6, c.lobes[1].alpha_y = 0.2;  // anisotropic along the tangent turned 0.4
  c.lobes[1].angle = 0.4;
  ClosureLobe view = c.lobes[0];  // and one that follows the view (wider across it the more the view grazes)
  view.alpha_x = view.alpha_y = 0.2;
  view.view_exponent = 1.5;
  c.lobes.push_back(view);
  const ClosureProposal proposal(c);
  for (const double theta : {0.0, 0.7, 1.4}) {
    const Vec3 o(std::sin(theta) * std::cos(2.0 * theta), std::sin(theta) * std::sin(2.0 * theta), std::cos(theta));
    const test::ChiSquareResult r = test::chi_square_in_directions(
        [&](double u1, double u2) { return proposal.sample_direction(o, u1, u2); }, [&](const Vec3& i) { return proposal.pdf(o, i); },
        200000, 11);
    EXPECT_GT(r.p_value, 1e-4) << theta << ": chi2 " << r.statistic << " dof " << r.dof;
  }
  // Negative control: the density of other closures (the sharp lobe a third broader) is refused.
  Closures other = c;
  other.lobes[0].alpha_x = other.lobes[0].alpha_y = 0.33;
  const ClosureProposal wrong(other);
  const Vec3 o(std::sin(0.7), 0.0, std::cos(0.7));
  const test::ChiSquareResult r = test::chi_square_in_directions(
      [&](double u1, double u2) { return proposal.sample_direction(o, u1, u2); }, [&](const Vec3& i) { return wrong.pdf(o, i); }, 200000, 11);
  EXPECT_LT(r.p_value, 1e-6);
}


// The mean squared distance of two lobes' Fresnel curves over mu uniform on [0, 1], summed over channels.
double fresnel_distance(const ClosureLobe& a, const ClosureLobe& b) {
  double sum = 0.0;
  for (int j = 0; j < 1000; ++j) {
    const Rgb d = a.fresnel_at((j + 0.5) / 1000.0) - b.fresnel_at((j + 0.5) / 1000.0);
    sum += glm::dot(d, d) / 1000.0;
  }
  return sum;
}

TEST(Closures, WithoutF82IsTheNearestGeneralizedSchlick) {
  ClosureLobe plain;  // a tint of 1: the curve is Schlick's, which the search must find
  plain.f0 = Rgb(0.3, 0.5, 0.7);
  plain.f82 = fresnel_schlick(plain.f0, 1.0 / 7.0);
  const ClosureLobe schlick = without_f82(plain);
  EXPECT_EQ(schlick.fresnel, ClosureLobe::Fresnel::schlick);
  EXPECT_NEAR(schlick.exponent, 5.0, 0.02);
  for (double f90 : {schlick.f90.r, schlick.f90.g, schlick.f90.b}) EXPECT_NEAR(f90, 1.0, 2e-3);

  ClosureLobe tinted = two_lobes().lobes[0];  // a gold-like tint that bends the curve down near grazing
  tinted.f82 = Rgb(0.6, 0.45, 0.3);
  const ClosureLobe near = without_f82(tinted);
  EXPECT_EQ(near.f0, tinted.f0);
  const double distance = fresnel_distance(near, tinted);
  // Dropping color82 (what MaterialX's OSL generator does) is the negative control; a nudged exponent or
  // f90 must not do better than the search.
  ClosureLobe dropped = tinted;
  dropped.f82 = fresnel_schlick(tinted.f0, 1.0 / 7.0);
  EXPECT_LT(distance, 0.3 * fresnel_distance(dropped, tinted)) << distance;  // 0.25 measured
  for (double de : {-0.1, 0.1}) {
    ClosureLobe nudged = near;
    nudged.exponent += de;
    EXPECT_GE(fresnel_distance(nudged, tinted), distance);
  }
  ClosureLobe nudged = near;
  nudged.f90 += Rgb(0.0, 0.01, 0.0);
  EXPECT_GE(fresnel_distance(nudged, tinted), distance);

  const ClosureLobe broad = two_lobes().lobes[1];  // a generalized Schlick lobe stays as it is
  EXPECT_EQ(without_f82(broad).exponent, broad.exponent);
  EXPECT_EQ(without_f82(broad).f90, broad.f90);
}

// A lobe that follows the view is, seen from any view, the anisotropic lobe of its alphas at that view along
// the view's azimuth: the same f whatever the view's azimuth, alpha across clamped at 1.
TEST(Closures, ViewAlignedLobeTurnsWithTheView) {
  Closures c;
  ClosureLobe l;
  l.alpha_x = l.alpha_y = 0.1;
  l.view_exponent = 2.0;
  l.fresnel = ClosureLobe::Fresnel::schlick;
  l.f0 = Rgb(0.5), l.f90 = Rgb(1.0);
  c.lobes = {l};
  const ClosureBrdf brdf(c);
  std::mt19937 rng(5);
  for (int k = 0; k < 200; ++k) {
    const Vec3 o = test::random_direction(rng), i = test::random_direction(rng);
    const double turn = 6.0 * k / 200.0, c2 = std::cos(turn), s2 = std::sin(turn);
    const auto turned = [&](const Vec3& v) { return Vec3(c2 * v.x - s2 * v.y, s2 * v.x + c2 * v.y, v.z); };
    const Rgb a = *brdf.eval(o, i), b = *brdf.eval(turned(o), turned(i));
    EXPECT_NEAR(a.r, b.r, 1e-9 * std::max(1.0, a.r)) << k;
    // The lobe as a plain anisotropic GGX in the view's frame.
    const TurnedFrame axes = TurnedFrame::of_azimuth(o);
    const Ndf ndf{NdfType::ggx, 0.1, std::min(0.1 / (o.z * o.z), 1.0)};
    const Vec3 lo = axes.to_frame(o), li = axes.to_frame(i), h = glm::normalize(lo + li);
    const double want = o.z > 0.0 && i.z > 0.0
                            ? (0.5 + 0.5 * std::pow(1.0 - clamp(glm::dot(li, h), 0.0, 1.0), 5.0)) * ndf.D(h) *
                                  smith_g2(Smith::correlated, ndf.lambda(lo), ndf.lambda(li)) / (4.0 * o.z * i.z)
                            : 0.0;
    EXPECT_NEAR(a.r, want, 1e-9 * std::max(1.0, want)) << k;
  }
}

TEST(ClosureFit, AlbedoSumAgreesWithTheBrdf) {
  // The fit's albedo (visible normals on a fixed grid) against the BRDF's as albedo_target draws it: within
  // 1% at every view (0.75% at most when written), under the fit's tolerance of 0.5 L* (about 1.3%).
  Closures c = two_lobes();
  c.lobes[1].view_exponent = 1.5;  // following the view, which the sums take along the view's azimuth
  const AlbedoTarget brdf = albedo_target(ClosureBrdf(c), ClosureProposal(c));
  for (std::size_t j = 0; j < brdf.cos_o.size(); ++j) {
    const Rgb sum = closure_albedo(c, brdf.cos_o[j]);
    for (int e = 0; e < 3; ++e) EXPECT_NEAR(sum[e], brdf.albedo[j][e], 0.01 * brdf.albedo[j][e]) << brdf.cos_o[j];
  }
}

TEST(ClosureFit, MomentTableAgreesWithTheDirectSum) {
  // The table's splines against the sums they interpolate, over the fit's ranges (each alpha 1e-3 to 1, e 0
  // to 10, every view of albedo_target; a quarter of the draws isotropic), and its derivatives against central
  // differences of itself.
  const AlbedoTarget target = albedo_target(ClosureBrdf(two_lobes()), ClosureProposal(two_lobes()));
  const auto table = VisibleMoments::at_views(target.cos_o);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double worst = 0.0, worst_slope = 0.0;
  for (int k = 0; k < 2000; ++k) {
    const std::size_t view = std::size_t(rng() % target.cos_o.size());
    const double lx = std::log(1e-3) * u(rng), ly = k % 4 == 1 ? lx : std::log(1e-3) * u(rng);
    const double e = k % 4 == 0 ? double(k / 4 % 8) : 0.25 + 9.75 * u(rng);
    const double ax = std::exp(lx), ay = std::exp(ly);
    const double direct = VisibleMoments::sum(target.cos_o[view], ax, ay, e);
    const VisibleMoments::Moment m = table->at(view, lx, ly, e);
    const double scale = VisibleMoments::sum(target.cos_o[view], ax, ay, 0.0);  // the albedo of F = 1
    worst = std::max(worst, std::abs(m.value - direct) / scale);
    constexpr double h = 1e-5;
    const double d_x = (table->at(view, lx + h, ly, e).value - table->at(view, lx - h, ly, e).value) / (2 * h);
    const double d_y = (table->at(view, lx, ly + h, e).value - table->at(view, lx, ly - h, e).value) / (2 * h);
    const double d_e = (table->at(view, lx, ly, e + h).value - table->at(view, lx, ly, e - h).value) / (2 * h);
    if (e > 0.3)
      worst_slope = std::max({worst_slope, std::abs(m.d_log_alpha_x - d_x) / scale, std::abs(m.d_log_alpha_y - d_y) / scale,
                              std::abs(m.d_exponent - d_e) / scale});
  }
  EXPECT_LT(worst, 3e-3);  // 0.25% when written: far under the fit's albedo tolerance (1.3%)
  EXPECT_LT(worst_slope, 1e-5);
}

TEST(ClosureFit, DerivativesMatchDifferences) {
  const MeasuredBins bins = measured_bins(HalfDiffTable::tabulate(ClosureBrdf(two_lobes())), 18, 90);
  Closures at = two_lobes();
  at.coat = Coat{0.04, 0.05};
  at.lobes[0].alpha_x = at.lobes[0].alpha_y = 0.1;  // away from the optimum: nonzero residuals
  at.lobes[1].exponent = 3.3;                         // between the table's nodes
  at.lobes[1].view_exponent = 1.3;                    // following the view: the derivatives in k too
  // The albedo's residuals too, against a target they are beyond the tolerance of (the lobes half as bright).
  Closures dim = two_lobes();
  for (ClosureLobe& l : dim.lobes) l.weight *= 0.5, l.f0 = 0.5 * l.f0, l.f90 = 0.5 * l.f90;
  const AlbedoTarget albedo = albedo_target(ClosureBrdf(dim), ClosureProposal(dim));
  EXPECT_LT(closure_jacobian_error(bins, at, &albedo), 1e-4);
}

// The bar: a two-lobe GGX mixture plus a body, written by the project's MERL writer and fitted as a
// user bakes it, comes back: two lobes, alphas and weights within 3%. (The broad lobe is generalized
// Schlick, whose weight is 1 and whose f0 and f90 scale it: they are checked as its weight.)
TEST(ClosureFit, RecoversATwoLobeMixtureWrittenInMerl) {
  TempDir dir;
  const Closures truth = two_lobes();
  HalfDiffTable::tabulate(ClosureBrdf(truth)).write(dir.file("mix.binary"));
  const FitResult fit = Fitter(FitOptions{}).fit(load_table(dir.file("mix.binary")));
  ASSERT_TRUE(fit.ok()) << fit.problem;
  const Closures& c = fit.closures.closures;
  ASSERT_EQ(c.lobes.size(), 2u);
  const ClosureLobe& sharp = c.lobes[0].alpha_x < c.lobes[1].alpha_x ? c.lobes[0] : c.lobes[1];
  const ClosureLobe& broad = c.lobes[0].alpha_x < c.lobes[1].alpha_x ? c.lobes[1] : c.lobes[0];
  const auto within = [](double got, double want) { return std::abs(got - want) <= 0.03 * want; };
  EXPECT_TRUE(within(sharp.alpha_x, 0.08)) << sharp.alpha_x;
  EXPECT_TRUE(within(broad.alpha_x, 0.35)) << broad.alpha_x;
  EXPECT_EQ(sharp.fresnel, ClosureLobe::Fresnel::f82_tint);
  EXPECT_TRUE(within(sharp.weight, 0.6)) << sharp.weight;
  EXPECT_EQ(broad.fresnel, ClosureLobe::Fresnel::schlick);
  for (int e = 0; e < 3; ++e) {
    EXPECT_TRUE(within(broad.f90[e], truth.lobes[1].f90[e])) << e << ": " << broad.f90[e];
    EXPECT_TRUE(within(broad.f0[e], truth.lobes[1].f0[e])) << e << ": " << broad.f0[e];
    EXPECT_TRUE(within(c.body[e], truth.body[e])) << e << ": " << c.body[e];
  }
  const MeasuredBins bins = error_bins(load_table(dir.file("mix.binary")));
  EXPECT_LT(closure_error(bins, c), 0.001);  // the bins' distance (the judged one adds the albedo's draws)
  // The one-lobe fits cannot hold it: the closures are far nearer.
  EXPECT_LT(closure_error(bins, c), 0.2 * parametric_error(bins, fit.smith, fit.ggx));
}

TEST(ClosureFit, OneLobeStaysOneLobe) {
  // A material that is one GGX lobe gets no second: no lobe that does not pay for itself.
  const FitResult fit = Fitter(FitOptions{}).fit(
      HalfDiffTable::tabulate(MicrofacetBrdf(Ndf::isotropic(NdfType::ggx, 0.2), Smith::correlated, Fresnel::schlick(Rgb(0.9, 0.6, 0.3)))));
  ASSERT_TRUE(fit.ok()) << fit.problem;
  ASSERT_EQ(fit.closures.closures.lobes.size(), 1u);
  EXPECT_NEAR(fit.closures.closures.lobes[0].alpha_x, 0.2, 0.006);
}

// closure_fresnel = schlick: the closures a renderer without the F82 term (MaterialX's OSL) renders exactly.
// On one F82-tint lobe whose tint dips below Schlick's curve, the fit's lobes are all generalized Schlick and
// no farther than the truth's own nearest Schlick curve (without_f82) is; the default fit, which may keep
// the F82 term, is nearer still (the control: the option changes the fit).
TEST(ClosureFit, SchlickOnlyClosuresHaveNoF82Term) {
  Closures truth;
  truth.body = Rgb(0.05);
  ClosureLobe lobe;
  lobe.alpha_x = lobe.alpha_y = 0.15;
  lobe.f0 = Rgb(0.9, 0.6, 0.3);
  lobe.f82 = Rgb(0.5, 0.5, 0.5);
  truth.lobes = {lobe};
  const HalfDiffTable table = HalfDiffTable::tabulate(ClosureBrdf(truth));
  FitOptions options;
  options.closure_fresnel = ClosureLobe::Fresnel::schlick;
  const FitResult schlick = Fitter(options).fit(table), f82 = Fitter(FitOptions{}).fit(table);
  ASSERT_TRUE(schlick.ok() && f82.ok()) << schlick.problem << f82.problem;
  for (const ClosureLobe& l : schlick.closures.closures.lobes) EXPECT_EQ(l.fresnel, ClosureLobe::Fresnel::schlick);
  Closures nearest = truth;
  nearest.lobes = {without_f82(lobe)};
  // The bins' distances (a fit's judged one adds its albedo's).
  const MeasuredBins bins = error_bins(table);
  const double nearest_error = closure_error(bins, nearest), schlick_error = closure_error(bins, schlick.closures.closures),
               f82_error = closure_error(bins, f82.closures.closures);
  EXPECT_LE(schlick_error, nearest_error) << nearest_error;
  EXPECT_LT(f82_error, 0.5 * schlick_error);
  std::printf("schlick %.5f nearest %.5f f82 %.5f lobes %zu\n", schlick_error, nearest_error, f82_error, schlick.closures.closures.lobes.size());
}

}  // namespace
}  // namespace facetfit
