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

}  // namespace

std::optional<FresnelCurve> fit_fresnel(const HalfDiffTable& table, const TabulatedNdf& ndf, Smith smith) {
  // Everything that depends on one axis only is computed once.
  std::array<double, kH> d_h{}, cos_h{}, sin_h{};
  for (int i = 0; i < kH; ++i) {
    d_h[i] = ndf.D(HalfDiffTable::theta_h(i));
    cos_h[i] = std::cos(HalfDiffTable::theta_h(i));
    sin_h[i] = std::sin(HalfDiffTable::theta_h(i));
  }
  std::array<double, kD> cos_d{}, sin_d{};
  for (int j = 0; j < kD; ++j) {
    cos_d[j] = std::cos(HalfDiffTable::theta_d(j));
    sin_d[j] = std::sin(HalfDiffTable::theta_d(j));
  }
  std::array<double, kP / 2 + 1> cos_p{};
  for (int k = 0; k <= kP / 2; ++k) cos_p[k] = std::cos(HalfDiffTable::phi_d(k));
  const G1Table g1(ndf);
  const float* channel[3] = {table.channel(0), table.channel(1), table.channel(2)};

  const Sums sums = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, kH), Sums{},
      [&](const tbb::blocked_range<int>& rows, Sums acc) {
        // The F = 1 model along one phi_d row, and 1 where both directions are above the horizon (0 below,
        // where no bin counts whatever the file holds).
        alignas(64) float model_row[kP];
        alignas(64) float above_row[kP];
        for (int i = rows.begin(); i < rows.end(); ++i) {
          for (int j = 0; j < kD; ++j) {
            // cos(theta_i) = A - B cos(phi_d), cos(theta_o) = A + B cos(phi_d) (docs/conventions.md).
            const double a = cos_h[i] * cos_d[j], b = sin_h[i] * sin_d[j];
            if (a <= 0.0) continue;  // theta_i + theta_o >= 180 degrees: the whole row is below the horizon
            // phi_d and pi - phi_d swap i and o: one model value serves both bins.
            for (int k = 0; k <= kP / 2; ++k) {
              const double mu_i = a - b * cos_p[k], mu_o = a + b * cos_p[k];
              const bool above = mu_i > 0.0 && mu_o > 0.0;
              const double f1 = above ? d_h[i] * smith_g2_from_g1(smith, g1(mu_o), g1(mu_i)) / (4.0 * mu_i * mu_o) : 0.0;
              model_row[k] = float(f1);
              above_row[k] = above ? 1.0f : 0.0f;
              if (k > 0 && k < kP / 2) {
                model_row[kP - k] = model_row[k];
                above_row[kP - k] = above_row[k];
              }
            }
            const std::size_t row = HalfDiffTable::index(i, j, 0);
            for (int c = 0; c < 3; ++c) {
              const float* values = channel[c] + row;
              // Branch-free so that it vectorizes: the weight is 1 for a valid bin, 0 otherwise. Row sums
              // in float (at most 180 terms), totals in double.
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
          }
        }
        return acc;
      },
      [](Sums x, const Sums& y) {
        x.join(y);
        return x;
      });

  FresnelCurve curve;
  for (int c = 0; c < 3; ++c) {
    // Entries without a usable measurement take the nearest usable ones, linearly in theta_d.
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
  return curve;
}

}  // namespace facetfit
