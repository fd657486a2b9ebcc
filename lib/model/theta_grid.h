// The extraction grid of Dupuy et al. 2015: nodes u_j = j / R, j = 0..R, at theta_j = u_j^2 pi/2.
//
// Squaring packs nodes near the normal, where smooth materials put their whole distribution. Between
// nodes a tabulated quantity is the uniform Catmull-Rom spline in u through the node values: linear in
// them (so integrals stay dot products with precomputed weights) and, for a peak a few nodes wide, 10x
// more accurate than linear interpolation (docs/extraction.md). At R = 90 the nodes below pi/2 are
// exactly MERL's theta_h bins, so a MERL table is read at its own samples.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/vec.h"

namespace facetfit {

// Weights of nodes k-1, k, k+1, k+2 of the uniform Catmull-Rom spline at fraction t of interval k.
inline std::array<double, 4> catmull_rom_weights(double t) {
  const double t2 = t * t, t3 = t2 * t;
  return {0.5 * (-t + 2.0 * t2 - t3), 0.5 * (2.0 - 5.0 * t2 + 3.0 * t3), 0.5 * (t + 4.0 * t2 - 3.0 * t3), 0.5 * (t3 - t2)};
}

struct ThetaGrid {
  int resolution = 90;

  int size() const { return resolution + 1; }
  double u(int j) const { return double(j) / resolution; }
  double theta(int j) const { return theta_of_u(u(j)); }

  static double theta_of_u(double u) { return u * u * 0.5 * kPi; }
  static double u_of_theta(double theta) { return std::sqrt(std::max(0.0, theta) / (0.5 * kPi)); }

  // The nodes and weights whose weighted sum is the spline at fraction t of interval j. Past the ends
  // the spline uses ghost nodes: u -> -u is the same theta, so node -1 mirrors node 1; node R + 1
  // continues the last interval linearly. Both are folded into the real nodes' weights.
  struct Stencil {
    int index[4];
    double weight[4];
  };
  Stencil stencil(int j, double t) const {
    const std::array<double, 4> w = catmull_rom_weights(t);
    Stencil s{{j - 1, j, j + 1, j + 2}, {w[0], w[1], w[2], w[3]}};
    if (j == 0) s.index[0] = 1;
    if (j + 2 > resolution) {  // ghost = 2 node(R) - node(R - 1)
      s.weight[2] += 2.0 * s.weight[3];
      s.weight[1] -= s.weight[3];
      s.weight[3] = 0.0;
      s.index[3] = resolution;
    }
    return s;
  }

  // Interval and fraction of theta (clamped to [0, pi/2]; NaN reads as 0: u_of_theta's max takes 0 over it).
  void locate(double theta, int* j, double* t) const {
    const double x = std::min(u_of_theta(theta), 1.0) * resolution;
    *j = std::min(int(x), resolution - 1);
    *t = x - *j;
  }

  // The spline through `values` (one per node) at theta.
  double interpolate(const std::vector<double>& values, double theta) const {
    int j;
    double t;
    locate(theta, &j, &t);
    const Stencil s = stencil(j, t);
    double v = 0.0;
    for (int q = 0; q < 4; ++q) v += s.weight[q] * values[std::size_t(s.index[q])];
    return v;
  }
};

}  // namespace facetfit
