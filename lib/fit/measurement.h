// The whole measurement as the fits on it see it: a strided subset of a MERL table's valid bins, each
// with its directions and its weight in the error metric, and that metric.
//
// Metric (docs/extraction.md, "Refinement"): the weighted mean over bins and channels of
//   (log(1 + f c) - log(1 + y c))^2,   c = (cos theta_i + cos theta_o) / 2,
// y the measurement, f the model. f c is the reflected radiance per unit irradiance, so the metric is
// absolute where that is small (a diffuse body, ~0.1) and relative where it is large (a glossy peak,
// 10-1000): no single bin can dominate, and noise in dark channels (RGL's near-zero blue, negative
// entries included) costs what its radiance is worth. Each bin also weighs by the solid-angle measure of
// its cell in (theta_h, theta_d, phi_d), so that the mean approximates an integral over direction pairs
// rather than favouring the bins MERL packs near the specular peak.
#pragma once

#include <cstdint>
#include <vector>

#include "core/brdf.h"
#include "io/merl.h"

namespace facetfit {

struct MeasuredBins {
  // Bins of one (theta_h, theta_d) row of the table: entries [begin, end) of the arrays below.
  struct Row {
    int theta_h = 0, theta_d = 0;  // MERL bin indices
    std::size_t begin = 0, end = 0;
  };
  std::vector<Row> rows;
  std::vector<Vec3> i, o;           // directions of each bin (phi_h = 0)
  std::vector<double> cos_mean;     // c = (cos theta_i + cos theta_o) / 2
  std::vector<double> weight;       // measure weight; the weights sum to one
  std::vector<Rgb> value;           // the measurement
  std::vector<std::uint8_t> valid;  // bit c set: channel c measured

  std::size_t size() const { return weight.size(); }
};

// Every valid bin with both directions above the horizon, theta_d and phi_d taken every `stride_d` and
// `stride_phi` bins (theta_h: every bin). Empty when the table has no valid bin.
MeasuredBins measured_bins(const MerlTable& table, int stride_d = 2, int stride_phi = 6);

// The metric's per-bin residual of one channel.
inline double log_residual(double model, double measured, double cos_mean) {
  return std::log1p(std::max(model, 0.0) * cos_mean) - std::log1p(std::max(measured * cos_mean, -0.5));
}

// Root of the metric's weighted mean square: how far `model` is from the measurement.
double measurement_error(const MeasuredBins& bins, const Brdf& model);

}  // namespace facetfit
