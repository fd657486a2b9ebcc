#include "fit/fresnel_fit.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>

namespace facetfit {

static_assert(FresnelCurve::kSize == HalfDiffTable::kThetaD, "one Fresnel entry per MERL theta_d bin");

namespace {

constexpr int kH = HalfDiffTable::kThetaH, kD = HalfDiffTable::kThetaD, kP = HalfDiffTable::kPhiD;

struct Sums {
  std::array<std::array<double, 3>, kD> measured{};
  std::array<std::array<double, 3>, kD> model{};
  std::array<std::array<std::int64_t, 3>, kD> count{};

  void join(const Sums& o) {
    for (int j = 0; j < kD; ++j)
      for (int c = 0; c < 3; ++c) {
        measured[j][c] += o.measured[j][c];
        model[j][c] += o.model[j][c];
        count[j][c] += o.count[j][c];
      }
  }
};

// Everything of the F = 1 model that depends on one axis only, computed once.
struct AxisTables {
  std::array<double, kH> d_h{}, cos_h{}, sin_h{};
  std::array<double, kD> cos_d{}, sin_d{};
  std::array<double, kP / 2 + 1> cos_p{};

  explicit AxisTables(const TabulatedNdf& ndf) {
    for (int i = 0; i < kH; ++i) {
      d_h[i] = ndf.D(HalfDiffTable::theta_h(i));
      cos_h[i] = std::cos(HalfDiffTable::theta_h(i));
      sin_h[i] = std::sin(HalfDiffTable::theta_h(i));
    }
    for (int j = 0; j < kD; ++j) {
      cos_d[j] = std::cos(HalfDiffTable::theta_d(j));
      sin_d[j] = std::sin(HalfDiffTable::theta_d(j));
    }
    for (int k = 0; k <= kP / 2; ++k) cos_p[k] = std::cos(HalfDiffTable::phi_d(k));
  }
};

// The F = 1 model along the phi_d row (theta_h i, theta_d j), and 1 where both directions are above the
// horizon (0 below, where no bin counts whatever the file holds). False where the whole row is below it.
bool model_row(const AxisTables& axes, const G1Table& g1, Smith smith, int i, int j, float* model, float* above) {
  // cos(theta_i) = A - B cos(phi_d), cos(theta_o) = A + B cos(phi_d) (docs/conventions.md).
  const double a = axes.cos_h[i] * axes.cos_d[j], b = axes.sin_h[i] * axes.sin_d[j];
  if (a <= 0.0) return false;  // theta_i + theta_o >= 180 degrees
  // phi_d and pi - phi_d swap i and o: one model value serves both bins.
  for (int k = 0; k <= kP / 2; ++k) {
    const double mu_i = a - b * axes.cos_p[k], mu_o = a + b * axes.cos_p[k];
    const bool up = mu_i > 0.0 && mu_o > 0.0;
    model[k] = float(up ? axes.d_h[i] * smith_g2_from_g1(smith, g1(mu_o), g1(mu_i)) / (4.0 * mu_i * mu_o) : 0.0);
    above[k] = up ? 1.0f : 0.0f;
    if (k > 0 && k < kP / 2) model[kP - k] = model[k], above[kP - k] = above[k];
  }
  return true;
}

// Adds one row of one channel to the sums. Branch-free so that it vectorizes: the weight is 1 for a valid
// bin, 0 otherwise. Row sums in float (at most 180 terms), totals in double.
void add_row(const float* values, const float* model_row, const float* above_row, Sums& acc, int j, int c) {
  float measured = 0.0f, model = 0.0f, count = 0.0f;
#pragma omp simd reduction(+ : measured, model, count)
  for (int k = 0; k < kP; ++k) {
    const bool valid = !HalfDiffTable::missing(values[k]);  // a missing bin is NaN: select, not multiply
    const float w = valid ? above_row[k] : 0.0f;
    measured += w * (valid ? values[k] : 0.0f);
    model += w * model_row[k];
    count += w;
  }
  acc.measured[j][c] += measured;
  acc.model[j][c] += model;
  acc.count[j][c] += std::int64_t(count);
}

// The measurement's and the F = 1 model's sums per theta_d entry and channel, over the valid bins.
Sums ratio_sums(const HalfDiffTable& table, const TabulatedNdf& ndf, Smith smith) {
  const AxisTables axes(ndf);
  const G1Table g1(ndf);
  const float* channel[3] = {table.channel(0), table.channel(1), table.channel(2)};
  return tbb::parallel_reduce(
      tbb::blocked_range<int>(0, kH), Sums{},
      [&](const tbb::blocked_range<int>& rows, Sums acc) {
        alignas(64) float model[kP];
        alignas(64) float above[kP];
        for (int i = rows.begin(); i < rows.end(); ++i)
          for (int j = 0; j < kD; ++j) {
            if (!model_row(axes, g1, smith, i, j, model, above)) continue;
            const std::size_t row = HalfDiffTable::index(i, j, 0);
            for (int c = 0; c < 3; ++c) add_row(channel[c] + row, model, above, acc, j, c);
          }
        return acc;
      },
      [](Sums x, const Sums& y) {
        x.join(y);
        return x;
      });
}

// Entries without a usable measurement take the nearest usable ones, linearly in theta_d.
void fill_between(FresnelCurve& curve, int c, const std::vector<int>& usable) {
  std::size_t u = 0;
  for (int j = 0; j < kD; ++j) {
    while (u + 1 < usable.size() && usable[u + 1] <= j) ++u;
    const int j0 = usable[u];
    if (j0 == j) continue;
    if (j < j0 || u + 1 == usable.size()) {
      curve.value[std::size_t(j)][c] = curve.value[std::size_t(j0)][c];
    } else {
      const int j1 = usable[u + 1];
      const double t = double(j - j0) / (j1 - j0);
      curve.value[std::size_t(j)][c] = (1.0 - t) * curve.value[std::size_t(j0)][c] + t * curve.value[std::size_t(j1)][c];
    }
  }
}

}  // namespace

std::optional<FresnelCurve> fit_fresnel(const HalfDiffTable& table, const TabulatedNdf& ndf, Smith smith) {
  const Sums sums = ratio_sums(table, ndf, smith);
  FresnelCurve curve;
  for (int c = 0; c < 3; ++c) {
    std::vector<int> usable;
    for (int j = 0; j < kD; ++j) {
      curve.count[std::size_t(j)][c] = sums.count[j][c];
      if (sums.model[j][c] > 0.0 && sums.count[j][c] > 0) {
        usable.push_back(j);
        // A reflectance is not negative: where noise around zero (RGL's negative entries) outweighs
        // the signal, the ratio is clamped rather than baked as a negative Fresnel factor.
        curve.value[std::size_t(j)][c] = std::max(0.0, sums.measured[j][c] / sums.model[j][c]);
      }
    }
    if (usable.empty()) return std::nullopt;
    fill_between(curve, c, usable);
  }
  return curve;
}

}  // namespace facetfit
