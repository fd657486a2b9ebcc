#include "fit/measurement.h"

#include <cmath>

#include "core/halfdiff.h"

namespace facetfit {

MeasuredBins measured_bins(const MerlTable& table, int stride_d, int stride_phi) {
  MeasuredBins bins;
  double total = 0.0;
  for (int i = 0; i < MerlTable::kThetaH; ++i) {
    // The cell's measure, 4 cos(theta_d) sin(theta_d) sin(theta_h) dtheta_h dtheta_d dphi_d (the Jacobian of
    // the half/difference parameterization), at the cell's centre; theta_h = u^2 pi/2, so dtheta_h = u pi du.
    // Each bin then weighs by cos(theta_i) cos(theta_o) too (below).
    const double u = (i + 0.5) / MerlTable::kThetaH;
    const double theta_h_mid = u * u * 0.5 * kPi;
    const double h_measure = std::sin(theta_h_mid) * u * kPi;
    for (int j = 0; j < MerlTable::kThetaD; j += stride_d) {
      const double theta_d_mid = (j + 0.5) / MerlTable::kThetaD * 0.5 * kPi;
      const double measure = 4.0 * std::cos(theta_d_mid) * std::sin(theta_d_mid) * h_measure;
      MeasuredBins::Row row{i, j, bins.size(), bins.size()};
      for (int k = 0; k < MerlTable::kPhiD; k += stride_phi) {
        const auto [wi, wo] = from_half_diff(MerlTable::theta_h(i), MerlTable::theta_d(j), MerlTable::phi_d(k));
        if (wi.z <= 1e-6 || wo.z <= 1e-6) continue;
        std::uint8_t valid = 0;
        Rgb v(0.0);
        for (int c = 0; c < 3; ++c) {
          const float x = table.value(c, i, j, k);
          if (!MerlTable::missing(x)) valid |= std::uint8_t(1u << c), v[c] = x;
        }
        if (!valid) continue;
        bins.i.push_back(wi);
        bins.o.push_back(wo);
        bins.cos_mean.push_back(0.5 * (wi.z + wo.z));
        bins.cos_h.push_back(std::cos(MerlTable::theta_h(i)));
        bins.cos_d.push_back(std::cos(MerlTable::theta_d(j)));
        Rgb lightness(0.0);
        for (int c = 0; c < 3; ++c)
          if (valid >> c & 1u) lightness[c] = metric_transform(v[c] * bins.cos_mean.back());
        bins.lightness.push_back(lightness);
        bins.weight.push_back(measure * wi.z * wo.z);
        bins.value.push_back(v);
        bins.valid.push_back(valid);
        total += measure;
      }
      row.end = bins.size();
      if (row.end > row.begin) bins.rows.push_back(row);
    }
  }
  if (total > 0.0)
    for (double& w : bins.weight) w /= total;
  return bins;
}

double measurement_error(const MeasuredBins& bins, const Brdf& model) {
  double sum = 0.0, norm = 0.0;
  for (std::size_t b = 0; b < bins.size(); ++b) {
    const auto f = model.eval(bins.o[b], bins.i[b]);
    const Rgb m = f ? *f : Rgb(0.0);
    for (int c = 0; c < 3; ++c) {
      if (!(bins.valid[b] >> c & 1u)) continue;
      const double r = metric_residual(m[c], bins.cos_mean[b], bins.lightness[b][c]).value;
      sum += bins.weight[b] * r * r;
      norm += bins.weight[b];
    }
  }
  return norm > 0.0 ? std::sqrt(sum / norm) : 0.0;
}

}  // namespace facetfit
