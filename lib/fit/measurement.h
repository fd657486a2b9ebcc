// The whole measurement as the fits on it see it: a strided subset of a MERL table's valid bins, each
// with its directions and its weight in the error metric, and that metric.
//
// Metric (docs/extraction.md, "Refinement"): the weighted mean over bins and channels of
//   (L(f c) - L(y c))^2,   c = (cos theta_i + cos theta_o) / 2,
// (a soft L1 loss of that difference for the grazing pairs: metric_residual below),
// y the measurement, f the model, L CIE L*'s lightness function of pi x (over 116). f c is the reflected
// radiance per unit irradiance, so a residual is a difference of lightness, what CIE Delta E measures of
// a rendering: compressive on glossy peaks (10-1000), steep but bounded near black, where dark channels
// and RGL's negative entries live. Each bin weighs by the projected solid angle of its cell,
// cos(theta_i) cos(theta_o) d(omega_i) d(omega_o): the mean approximates an integral over direction pairs
// rather than favouring the bins MERL packs near the specular peak, and over the pairs as a rendering
// sees them (light arrives weighted by cos theta_i, a surface covers pixels in proportion to
// cos theta_o), so grazing pairs, which plain solid angle favours, do not outweigh what is on screen.
//
// A source with two one-sided estimates (OneSidedMeasurement: RGL) gives each bin twice, once per
// estimate T(p, q) = y(p, q) cos theta_q read from the data of p, with c = cos theta_q and half the
// bin's weight: the residual L(f cos theta_q) - L(T(p, q)) compares the model with what the file measured,
// undivided by a grazing cosine, as a renderer reading p's data (Mitsuba's `measured`, p the viewer) shows
// it. An estimate whose p lies past the measured elevations is left out (RglBsdf::one_sided).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/brdf.h"
#include "model/proposal.h"
#include "io/half_diff_lattice.h"
#include "io/merl.h"

namespace facetfit {

struct MeasuredBins {
  // Bins of one (theta_h, theta_d) row of the table: entries [begin, end) of the arrays below.
  struct Row {
    double theta_h = 0.0, theta_d = 0.0;  // radians, shared by the row's bins
    std::size_t begin = 0, end = 0;
  };
  std::vector<Row> rows;
  std::vector<Vec3> i, o;           // directions of each bin (MERL bins: phi_h = 0); of a one-sided estimate, o is its view
  std::vector<double> cosine;       // c: (cos theta_i + cos theta_o) / 2, or cos theta_q of a one-sided estimate
  std::vector<double> cos_h, cos_d; // cos theta_h, cos theta_d (= i . h)
  std::vector<double> weight;       // measure weight, over the total measure of the bins taken
  std::vector<Rgb> lightness;       // metric_transform(y c): the residuals' fixed half
  std::vector<std::uint8_t> valid;  // bit c set: channel c measured

  std::size_t size() const { return weight.size(); }
};

// Every valid bin with both directions above the horizon, theta_d and phi_d taken every `stride_d` and
// `stride_phi` bins (theta_h: every bin); from the table's source_one_sided() where it has one, its two
// estimates. A table whose source measured at nodes of its own (source_samples(): a UTIA file) gives
// those nodes instead, every one, one row each: the table resamples between them, and a fit of the
// resampled table fits the interpolation (docs/extraction.md). Empty when there is no valid bin.
MeasuredBins measured_bins(const HalfDiffTable& table, int stride_d, int stride_phi);

// The nodes of an anisotropic source's lattice (io/half_diff_lattice.h), every `stride`-th of each
// (theta_h, theta_d) row's phi_h x phi_d nodes (the start staggered from row to row); a row is one
// (theta_h, theta_d) pair of the lattice. Empty for an empty lattice.
MeasuredBins measured_bins(const HalfDiffLattice& lattice, int stride);

// What an anisotropic fit of the table's source reads: the pairs it was measured at
// (HalfDiffTable::source_anisotropic_samples: a UTIA file's, one in `stride` spread over them by a hash of
// the index) or else its lattice (source_half_diff, every `stride`-th as above). Empty when the source
// has neither.
MeasuredBins anisotropic_bins(const HalfDiffTable& table, int stride);

// The bin sets of the fits: the tabulated lobe's refinement solves on the sparse one (6.4k bins: the
// fitted distances move by < 1% between 93k bins and this), the parametric fits (8 to 12 unknowns) on
// a sparser one (2.1k bins: their distances move by < 0.5% from the 6.4k set, at 40% of the time),
// and every distance is measured on the densest, mostly disjoint one (31k bins; of a source with two
// one-sided estimates every other phi_d of those, 15.5k bins and 31k estimates: the six RGL files'
// distances move by < 2% and no choice between fits changes, at 15% less of the fit's time). A source
// measured at nodes of its own (a UTIA file) has no other measurement: the three sets are its 1,728
// nodes, so its distances are measured on what was fitted.
inline MeasuredBins solve_bins(const HalfDiffTable& table) { return measured_bins(table, 6, 30); }
inline MeasuredBins parametric_bins(const HalfDiffTable& table) { return measured_bins(table, 9, 60); }
// The closure fit (fit/closure_fit.h: 13 to 38 unknowns) solves on sparser bins still: theta_d every 18th,
// phi_d every 30th (2.5k). Its lobes that follow the view are wider across the plane of incidence than along
// it, which only phi_d tells apart: with every 90th phi_d (two of them, 0.8k bins) the fourteen RGL
// materials' closures rendered 0.04 farther from Mitsuba's on average; every 15th, 0.02 nearer at 3.5x the time.
inline MeasuredBins closure_bins(const HalfDiffTable& table) { return measured_bins(table, 18, 30); }
inline MeasuredBins error_bins(const HalfDiffTable& table) { return measured_bins(table, 3, table.source_one_sided() ? 24 : 12); }

// The metric's transform of x = f c: CIE L*'s lightness function of pi x (cube root, linear near
// black, so its slope at zero is bounded). Negative values (RGL noise around zero) take the same
// function mirrored about zero: without the mirror, the linear part would let a handful of large
// negative entries (one-sided estimates divided by grazing cosines) outweigh everything else, which
// doubled the distance of every fit on one material. `slope`, if given, receives d transform / dx.
inline double metric_transform(double x, double* slope = nullptr) {
  constexpr double kDelta = 6.0 / 29.0, kDelta3 = kDelta * kDelta * kDelta, kLinear = 1.0 / (3.0 * kDelta * kDelta);
  const double t = kPi * std::abs(x);
  double lightness, d;
  if (t > kDelta3) {
    lightness = cube_root(t);  // core/vec.h's, not the C library's slower cbrt: the fits call this per residual
    d = kPi / (3.0 * lightness * lightness);
  } else {
    lightness = t * kLinear + 4.0 / 29.0;
    d = kPi * kLinear;
  }
  if (slope) *slope = d;
  return x >= 0.0 ? lightness : 8.0 / 29.0 - lightness;
}

// Pairs with a direction more than 70 degrees from the normal (docs/extraction.md, "Grazing pairs"):
// where a gonioreflectometer measures least reliably (an RGL file's last measured elevation is 78.5
// degrees, its two one-sided estimates part by 27% at 86), and where a residual of several units of
// lightness says more about the instrument, or about what one isotropic lobe cannot hold, than about
// the surface a rendering shows. Their residuals pass through a soft L1 loss of scale 4 units of L*:
// quadratic below it, growing as their size rather than its square beyond, so the
// few-pixel rim no longer pulls the lobe away from the pairs that fill the screen.
constexpr double kGrazingCos = 0.34202014332566873;  // cos(70 degrees)
constexpr double kGrazingScale = 4.0 / 116.0;        // 4 units of L*, in the residuals' units (L* / 116)
inline bool grazing_pair(const Vec3& o, const Vec3& i) { return std::min(o.z, i.z) < kGrazingCos; }

// The metric's per-bin residual of one channel given the measurement's `lightness` (MeasuredBins: the
// model is nonnegative; the measurement is kept as it is), and its derivative with respect to the model.
// For a grazing pair, psi(r) = r sqrt(2 / (1 + q)), q = sqrt(1 + r^2 / s^2), s = kGrazingScale: its square
// is the soft L1 loss 2 s^2 (q - 1), written without the difference that loses digits for small r; its
// derivative 1 / (q sqrt(2 / (1 + q))) is 1 at r = 0.
struct MetricResidual {
  double value = 0.0, slope = 0.0;
};
inline MetricResidual metric_residual(double model, double cosine, double lightness, bool grazing) {
  double slope = 0.0;
  const double r = metric_transform(std::max(model, 0.0) * cosine, &slope) - lightness;
  const double dr = model >= 0.0 ? cosine * slope : 0.0;
  if (!grazing || !std::isfinite(r)) return {r, dr};  // an infinite r would give inf x 0 below
  const double q = std::sqrt(1.0 + (r / kGrazingScale) * (r / kGrazingScale)), s = std::sqrt(2.0 / (1.0 + q));
  return {r * s, dr / (q * s)};
}

// The directional albedo rho(o) = integral of f(o, i) cos theta_i over i of what a fit should return (the
// measurement), at views uniform in sin theta_o, each with its share of a sphere's pixels. The closures
// (fit/closure_fit.h) and the tabulated lobe (fit/refine.h) match it beside the bins: the bins weigh grazing
// pairs down and an RGL file has none past 78.5 degrees, so what a rendering under an environment shows of
// every pixel, how much light the material returns from all directions, is held by this alone.
struct AlbedoTarget {
  std::vector<double> cos_o, weight;  // the weights sum to the albedo residuals' share beside the bins' 1
  std::vector<Rgb> albedo, lightness;  // lightness: metric_transform(albedo / pi)
  int grid = 0;  // drawn on a jittered grid x grid per view
};
// `model`'s albedo by `proposal`'s draws (jittered in a grid x grid of strata per view, where the grid's
// own midpoints, through a mixture's choice of part, were off by 1%) at 16 views. The residuals' share: 10
// times the bins' (on the six RGL materials a share of 1 to 3 left a colour-shifting film's rendering
// farther from Mitsuba's).
AlbedoTarget albedo_target(const Brdf& model, const Proposal& proposal, double share = 10.0, int grid = 128);
// `model`'s albedo at cos theta_o of each of `cos_o` by `proposal`'s draws on a jittered grid x grid.
std::vector<Rgb> directional_albedo(const Brdf& model, const Proposal& proposal, const std::vector<double>& cos_o, int grid);

// The residual of a fit's albedo rho at view j and channel c, and its derivative in rho:
//   sqrt(weight_j) D(L(rho) - L(target_jc)),  L = metric_transform(rho / pi) (CIE L* of rho, over 116),
// D(x) = sign(x) max(0, |x| - kAlbedoTolerance). The tolerance, 0.5 units of L* (about 1.3% of the albedo),
// is of the order of the target's and the closures' moments' own errors (0.4% and 0.3%): with errors of 1% (a
// target from a grid's midpoints, visible normals on 8 x 8 numbers) a two-lobe GGX mixture written in MERL came
// back with a weight 5% off (tests/fit/test_closures.cpp).
constexpr double kAlbedoTolerance = 0.5 / 116.0;
MetricResidual albedo_residual(const AlbedoTarget& target, std::size_t view, int channel, double rho);

// How far an albedo at the target's views is from it: the root of the weighted sum of squared lightness
// differences (no tolerance), over channels, with the target's weights (their sum is the share beside the
// bins' 1).
double albedo_distance(const AlbedoTarget& target, const std::vector<Rgb>& albedo);
// The same of `model`, its albedo drawn by `proposal` (the model's own: another's misses a sharper lobe) on
// the target's grid, with the target's random numbers.
double albedo_distance(const AlbedoTarget& target, const Brdf& model, const Proposal& proposal);

// The distance a fit is judged by (FitResult's errors, the recommendation, the closures' and the tabulated
// candidates' choices): the bins' and the albedo's, sqrt(bins^2 + albedo^2). Ranking the five representations
// of the fourteen RGL materials by it, the one taken renders 0.06 Delta E from the best of the five on
// average; by the bins' alone, 0.32 (docs/extraction.md).
inline double judged_distance(double bins, double albedo) { return std::sqrt(bins * bins + albedo * albedo); }

// Every n-th row of `bins`, their weights summing to 1 again: a sparser set of the same kind.
MeasuredBins every_nth_row(const MeasuredBins& bins, int n);

// Root of the metric's weighted mean square: how far `model` is from the measurement.
double measurement_error(const MeasuredBins& bins, const Brdf& model);

}  // namespace facetfit
