// Piecewise-constant distributions, sampled by inverting their running sums: the one sampler behind the
// environment map's pixels (2D), the tabulated model's visible normals and the renderer's visible slopes
// (1D rows, model/visible_slopes.h). Inverting keeps a draw continuous in u: two similar lobes draw similar
// directions from the same numbers, so the noise of their renders largely cancels in a difference (the
// report's). The RGL warp (io/rgl.cpp) is not one of them: the format defines a bilinear density, which
// Mitsuba 3 inverts as such, and the parity with it needs that density.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace facetfit {

// The interval k of a normalised running sum cdf[0..n] (cdf[0] = 0, cdf[n] = 1, nondecreasing) in which
// u in [0, 1) falls, and u's fraction t within it. Intervals without mass are never chosen.
inline int sample_cdf(const double* cdf, int n, double u, double* t) {
  int k = int(std::upper_bound(cdf, cdf + n + 1, u) - cdf) - 1;
  k = std::clamp(k, 0, n - 1);
  const double m = cdf[k + 1] - cdf[k];
  *t = m > 0.0 ? std::clamp((u - cdf[k]) / m, 0.0, 1.0) : 0.5;
  return k;
}

// Which of two distributions mixed with weights 1 - t and t a u in [0, 1) draws (0 or 1), u rescaled to
// [0, 1) within that one's share: the draw from it needs no number of its own.
inline int pick_of_two(double t, double* u) {
  int which = 0;
  if (*u < 1.0 - t) {
    *u /= 1.0 - t;
  } else {
    *u = (*u - (1.0 - t)) / t;
    which = 1;
  }
  *u = std::clamp(*u, 0.0, 1.0 - 1e-16);
  return which;
}

// A guide to the running sums cdf[0..n], appended to `guide`: entry g (0..size) is the last cell k whose
// sum cdf[k] is <= g / size (n at g = size). The cell a u in [g, g + 1) / size falls in lies between
// entries g and g + 1, so the SIMD samplers search there rather than over the whole row; size is a power
// of two, so u size is exact.
inline void append_cdf_guide(const double* cdf, int n, int size, std::vector<std::int64_t>& guide) {
  std::int64_t k = 0;
  for (int g = 0; g <= size; ++g) {
    const double u = double(g) / size;
    while (k < n && cdf[k + 1] <= u) ++k;
    guide.push_back(k);
  }
}

// A density over [0, 1]^2 constant on an nx x ny grid of cells, proportional to given weights: rows are
// drawn from the marginal, then the cell from the row's conditional. A row without weight is uniform.
class PiecewiseConstant2D {
 public:
  PiecewiseConstant2D() = default;
  // weights: ny rows of nx cells, each >= 0, not all zero.
  PiecewiseConstant2D(const std::vector<double>& weights, int nx, int ny)
      : nx_(nx), ny_(ny), conditional_(std::size_t(ny) * (nx + 1)), marginal_(std::size_t(ny) + 1), density_(weights.size()) {
    double total = 0.0;
    for (int y = 0; y < ny; ++y) {
      double* cdf = conditional_.data() + std::size_t(y) * (nx + 1);
      for (int x = 0; x < nx; ++x) cdf[x + 1] = cdf[x] + weights[std::size_t(y) * nx + x];
      marginal_[std::size_t(y) + 1] = marginal_[std::size_t(y)] + cdf[nx];
      total += cdf[nx];
      const double row = cdf[nx];
      for (int x = 0; x <= nx; ++x) cdf[x] = row > 0.0 ? cdf[x] / row : double(x) / nx;
    }
    for (double& v : marginal_) v /= total;
    for (std::size_t k = 0; k < weights.size(); ++k) density_[k] = weights[k] / total * double(nx) * double(ny);
  }

  struct Sample {
    double u, v;  // the point of [0, 1]^2
    int x, y;     // its cell
  };
  Sample sample(double u1, double u2) const {
    double tv, tu;
    const int y = sample_cdf(marginal_.data(), ny_, u1, &tv);
    const int x = sample_cdf(conditional_.data() + std::size_t(y) * (nx_ + 1), nx_, u2, &tu);
    return {(x + tu) / nx_, (y + tv) / ny_, x, y};
  }
  // Density over [0, 1]^2 in cell (x, y).
  double pdf(int x, int y) const { return density_[std::size_t(y) * nx_ + x]; }

 private:
  int nx_ = 0, ny_ = 0;
  std::vector<double> conditional_;  // ny rows of nx + 1 running sums
  std::vector<double> marginal_;     // ny + 1
  std::vector<double> density_;      // per cell
};

}  // namespace facetfit
