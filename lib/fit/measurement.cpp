#include "fit/measurement.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <utility>

#include "core/halfdiff.h"

namespace facetfit {

namespace {

// Appends one bin: its directions, the cell's measure in the parameterization (times cos(theta_i)
// cos(theta_o) here, see measurement.h) and the measured y c for the metric's cosine c, NaN where a
// channel is missing. Returns the measure it added to the total, 0 for a bin left out (below the
// horizon, nothing measured).
double add_bin(MeasuredBins& bins, const Vec3& wo, const Vec3& wi, double cos_h, double cos_d, double measure,
               const Rgb& reflected, double cosine) {
  if (wi.z <= 1e-6 || wo.z <= 1e-6) return 0.0;
  std::uint8_t valid = 0;
  Rgb lightness(0.0);
  for (int c = 0; c < 3; ++c)
    if (!std::isnan(reflected[c])) valid |= std::uint8_t(1u << c), lightness[c] = metric_transform(reflected[c]);
  if (!valid) return 0.0;
  bins.i.push_back(wi);
  bins.o.push_back(wo);
  bins.cosine.push_back(cosine);
  bins.cos_h.push_back(cos_h);
  bins.cos_d.push_back(cos_d);
  bins.lightness.push_back(lightness);
  bins.weight.push_back(measure * (wi.z * wo.z));  // the same for a bin's two estimates, o and i swapped
  bins.valid.push_back(valid);
  return measure;
}

// A reciprocal table's bin: y c with c the mean cosine.
double add_bin(MeasuredBins& bins, const Vec3& wo, const Vec3& wi, double cos_h, double cos_d, double measure, const Rgb& y) {
  const double cosine = 0.5 * (wo.z + wi.z);
  return add_bin(bins, wo, wi, cos_h, cos_d, measure, y * cosine, cosine);
}

// The bin's two one-sided estimates, each with half its measure and its own view: o the direction p whose
// data it was read from (a renderer's viewer), i the other; one past the measured elevations is left out.
double add_one_sided(MeasuredBins& bins, const OneSidedMeasurement& source, const Vec3& wo, const Vec3& wi, double cos_h,
                     double cos_d, double measure) {
  if (wi.z <= 1e-6 || wo.z <= 1e-6) return 0.0;
  double added = 0.0;
  for (const auto& [p, q] : {std::pair{wo, wi}, std::pair{wi, wo}})
    if (const std::optional<Rgb> t = source.one_sided(p, q)) added += add_bin(bins, p, q, cos_h, cos_d, 0.5 * measure, *t, q.z);
  return added;
}

void normalize_weights(MeasuredBins& bins, double total) {
  if (total > 0.0)
    for (double& w : bins.weight) w /= total;
}

// A source's own nodes, one row each (rows only group bins: a node and its mirror (i, o swapped) share
// their half/difference angles, and so do the pole's nodes), one in `stride` of them. Picked by
// Fibonacci hashing of the index (kept when k times 2^64 / golden ratio, mod 2^64, falls in the lowest
// 1/stride of the range), not every stride-th: a source's samples come in nested loops over its nodes,
// whose periods every stride-th would alias with (of a UTIA file's 48 azimuths, a stride of 24 keeps two).
// Spread this way every off-pole view and light direction of a UTIA file keeps 6 to 14 of its 288 pairs
// at stride 24 (tests/fit/test_refine.cpp); the low bits of the same product, taken modulo the stride, left
// 31 of them out.
MeasuredBins sample_bins(const std::vector<MeasuredSample>& samples, std::uint64_t stride = 1) {
  MeasuredBins bins;
  double total = 0.0;
  const std::uint64_t kept = stride > 1 ? ~std::uint64_t(0) / stride : ~std::uint64_t(0);
  for (std::size_t k = 0; k < samples.size(); ++k) {
    if (std::uint64_t(k) * 0x9E3779B97F4A7C15ull > kept) continue;
    const MeasuredSample& s = samples[k];
    const HalfDiff hd = to_half_diff(s.o, s.i);
    MeasuredBins::Row row{hd.theta_h, hd.theta_d, bins.size(), bins.size()};
    total += add_bin(bins, s.o, s.i, std::cos(hd.theta_h), std::cos(hd.theta_d), s.measure, s.f);
    row.end = bins.size();
    if (row.end > row.begin) bins.rows.push_back(row);
  }
  normalize_weights(bins, total);
  return bins;
}

}  // namespace

MeasuredBins measured_bins(const HalfDiffTable& table, int stride_d, int stride_phi) {
  if (table.source_samples()) return sample_bins(*table.source_samples());
  MeasuredBins bins;
  const OneSidedMeasurement* one_sided = table.source_one_sided().get();
  double total = 0.0;
  for (int i = 0; i < HalfDiffTable::kThetaH; ++i) {
    // The cell's measure, 4 cos(theta_d) sin(theta_d) sin(theta_h) dtheta_h dtheta_d dphi_d (the Jacobian of
    // the half/difference parameterization), at the cell's centre; theta_h = u^2 pi/2, so dtheta_h = u pi du.
    const double u = (i + 0.5) / HalfDiffTable::kThetaH;
    const double theta_h_mid = u * u * 0.5 * kPi;
    const double h_measure = std::sin(theta_h_mid) * u * kPi;
    const CosSin h(HalfDiffTable::theta_h(i));
    for (int j = 0; j < HalfDiffTable::kThetaD; j += stride_d) {
      const double theta_d_mid = (j + 0.5) / HalfDiffTable::kThetaD * 0.5 * kPi;
      const double measure = 4.0 * std::cos(theta_d_mid) * std::sin(theta_d_mid) * h_measure;
      MeasuredBins::Row row{HalfDiffTable::theta_h(i), HalfDiffTable::theta_d(j), bins.size(), bins.size()};
      const CosSin d(HalfDiffTable::theta_d(j));
      for (int k = 0; k < HalfDiffTable::kPhiD; k += stride_phi) {
        const auto [wo, wi] = from_half_diff(h, d, CosSin(HalfDiffTable::phi_d(k)));
        if (one_sided) {
          total += add_one_sided(bins, *one_sided, wo, wi, h.cos, d.cos, measure);
          continue;
        }
        Rgb v;
        for (int c = 0; c < 3; ++c) v[c] = table.value(c, i, j, k);  // missing: NaN (HalfDiffTable::missing)
        total += add_bin(bins, wo, wi, h.cos, d.cos, measure, v);
      }
      row.end = bins.size();
      if (row.end > row.begin) bins.rows.push_back(row);
    }
  }
  normalize_weights(bins, total);
  return bins;
}

MeasuredBins anisotropic_bins(const HalfDiffTable& table, int stride) {
  if (table.source_anisotropic_samples()) return sample_bins(*table.source_anisotropic_samples(), std::uint64_t(std::max(stride, 1)));
  return measured_bins(table.source_half_diff(), stride);
}

MeasuredBins measured_bins(const HalfDiffLattice& lattice, int stride) {
  using L = HalfDiffLattice;
  MeasuredBins bins;
  if (lattice.empty()) return bins;
  double total = 0.0;
  for (int h = 0; h < L::kThetaH; ++h)
    for (int d = 0; d < L::kThetaD; ++d) {
      MeasuredBins::Row row{L::theta_h(h), L::theta_d(d), bins.size(), bins.size()};
      // Strided over the whole (phi_h, phi_d) square, so every azimuth of the half vector is kept.
      for (int a = (h + d) % stride; a < L::kPhiH * L::kPhiD; a += stride) {
        const int ph = a / L::kPhiD, pd = a % L::kPhiD;
        const auto [wo, wi] = L::directions(h, ph, d, pd);
        total += add_bin(bins, wo, wi, std::cos(L::theta_h(h)), std::cos(L::theta_d(d)), L::measure(h, d),
                         lattice.value[L::index(h, ph, d, pd)]);
      }
      row.end = bins.size();
      if (row.end > row.begin) bins.rows.push_back(row);
    }
  normalize_weights(bins, total);
  return bins;
}

MeasuredBins every_nth_row(const MeasuredBins& bins, int n) {
  MeasuredBins out;
  double total = 0.0;
  for (std::size_t r = 0; r < bins.rows.size(); r += std::size_t(std::max(n, 1))) {
    MeasuredBins::Row row = bins.rows[r];
    const std::size_t begin = out.size();
    for (std::size_t k = row.begin; k < row.end; ++k) {
      out.i.push_back(bins.i[k]), out.o.push_back(bins.o[k]), out.cosine.push_back(bins.cosine[k]);
      out.cos_h.push_back(bins.cos_h[k]), out.cos_d.push_back(bins.cos_d[k]), out.weight.push_back(bins.weight[k]);
      out.lightness.push_back(bins.lightness[k]), out.valid.push_back(bins.valid[k]);
      total += bins.weight[k];
    }
    row.begin = begin, row.end = out.size();
    out.rows.push_back(row);
  }
  normalize_weights(out, total);
  return out;
}

double measurement_error(const MeasuredBins& bins, const Brdf& model) {
  double sum = 0.0, norm = 0.0;
  for (std::size_t b = 0; b < bins.size(); ++b) {
    const auto f = model.eval(bins.o[b], bins.i[b]);
    const Rgb m = f ? *f : Rgb(0.0);
    const bool grazing = grazing_pair(bins.o[b], bins.i[b]);
    for (int c = 0; c < 3; ++c) {
      if (!(bins.valid[b] >> c & 1u)) continue;
      const double r = metric_residual(m[c], bins.cosine[b], bins.lightness[b][c], grazing).value;
      sum += bins.weight[b] * r * r;
      norm += bins.weight[b];
    }
  }
  return norm > 0.0 ? std::sqrt(sum / norm) : 0.0;
}

std::vector<Rgb> directional_albedo(const Brdf& model, const Proposal& proposal, const std::vector<double>& cos_o, int grid) {
  std::vector<Rgb> albedo(cos_o.size(), Rgb(0.0));
  // Views concurrently, each with its own numbers: jitter within the strata (a grid's midpoints, through the
  // mixture's choice of part, alias).
  tbb::parallel_for(std::size_t(0), cos_o.size(), [&](std::size_t j) {
    std::mt19937_64 rng(std::uint64_t(j) + 1);
    std::uniform_real_distribution<double> jitter(0.0, 1.0);
    const Vec3 o(std::sqrt(std::max(0.0, 1.0 - cos_o[j] * cos_o[j])), 0.0, cos_o[j]);
    Rgb sum(0.0);
    for (int a = 0; a < grid; ++a)
      for (int b = 0; b < grid; ++b) {
        const auto i = proposal.sample_direction(o, (a + jitter(rng)) / grid, (b + jitter(rng)) / grid);
        const double pdf = i ? proposal.pdf(o, *i) : 0.0;
        const auto f = i && pdf > 0.0 ? model.eval(o, *i) : std::nullopt;
        if (f) sum += *f * (i->z / pdf);
      }
    albedo[j] = sum / double(grid * grid);
  });
  return albedo;
}

AlbedoTarget albedo_target(const Brdf& model, const Proposal& proposal, double share, int grid) {
  constexpr int kViews = 16;
  AlbedoTarget t;
  t.grid = grid;
  for (int j = 0; j < kViews; ++j) {
    // Nodes uniform in r = sin theta_o, a sphere's image radius: each stands for an annulus of its pixels.
    const double r = (j + 0.5) / kViews;
    t.cos_o.push_back(std::sqrt(1.0 - r * r));
    t.weight.push_back(share * 2.0 * r / kViews);
  }
  t.albedo = directional_albedo(model, proposal, t.cos_o, grid);
  for (const Rgb& albedo : t.albedo)
    t.lightness.push_back(Rgb(metric_transform(albedo.r * kInvPi), metric_transform(albedo.g * kInvPi), metric_transform(albedo.b * kInvPi)));
  return t;
}

double albedo_distance(const AlbedoTarget& target, const std::vector<Rgb>& albedo) {
  double sum = 0.0;
  for (std::size_t j = 0; j < target.cos_o.size(); ++j)
    for (int c = 0; c < 3; ++c) {
      const double d = metric_transform(albedo[j][c] * kInvPi) - target.lightness[j][c];
      sum += target.weight[j] * d * d;
    }
  return std::sqrt(sum / 3.0);
}

double albedo_distance(const AlbedoTarget& target, const Brdf& model, const Proposal& proposal) {
  return albedo_distance(target, directional_albedo(model, proposal, target.cos_o, target.grid));
}

MetricResidual albedo_residual(const AlbedoTarget& target, std::size_t view, int channel, double rho) {
  double slope = 0.0;
  const double difference = metric_transform(rho * kInvPi, &slope) - target.lightness[view][channel];
  const double beyond = std::max(0.0, std::abs(difference) - kAlbedoTolerance), w = std::sqrt(target.weight[view]);
  return {w * std::copysign(beyond, difference), beyond > 0.0 ? w * slope * kInvPi : 0.0};
}

}  // namespace facetfit
