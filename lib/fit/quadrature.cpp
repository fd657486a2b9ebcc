#include "fit/quadrature.h"

#include <tbb/parallel_for.h>

#include <cmath>

namespace facetfit {

Quadrature::Quadrature(int resolution, int points_per_interval) : grid_{resolution} {
  const int n = size();
  std::vector<double> gx, gw;
  gauss_legendre(points_per_interval, gx, gw);
  const double du = 1.0 / resolution;
  for (int j = 0; j < resolution; ++j) {
    for (int q = 0; q < points_per_interval; ++q) {
      const double u = (j + gx[std::size_t(q)]) * du;
      // theta = u^2 pi/2, so d(theta) = pi u du.
      nodes_.push_back({j, gx[std::size_t(q)], ThetaGrid::theta_of_u(u), gw[std::size_t(q)] * du * kPi * u});
    }
  }

  // Spreads a node's contribution onto the grid nodes its spline value depends on.
  const auto spread = [this](double* row, const Node& node, double value) {
    const ThetaGrid::Stencil st = grid_.stencil(node.interval, node.t);
    for (int q = 0; q < 4; ++q) row[st.index[q]] += st.weight[q] * value;
  };

  projected_area_.assign(std::size_t(n), 0.0);
  abs_slope_.assign(std::size_t(n), 0.0);
  sq_slope_.assign(std::size_t(n), 0.0);
  for (const Node& node : nodes_) {
    const double s = std::sin(node.theta), c = std::cos(node.theta);
    // dw = sin(theta) d(theta) d(phi); the phi integrals of 1, |cos(phi)|, cos^2(phi) are 2 pi, 4, pi.
    spread(projected_area_.data(), node, 2.0 * kPi * c * s * node.weight);
    spread(abs_slope_.data(), node, 4.0 * s * s * node.weight);
    if (node.interval < resolution - 1) spread(sq_slope_.data(), node, kPi * s * s * s / c * node.weight);
  }

  positive_.assign(std::size_t(n) * n, 0.0);
  absolute_.assign(std::size_t(n) * n, 0.0);
  tbb::parallel_for(0, n, [&](int k) {
    const double sk = std::sin(grid_.theta(k)), ck = std::cos(grid_.theta(k));
    double* pos = positive_.data() + std::size_t(k) * n;
    double* abs = absolute_.data() + std::size_t(k) * n;
    for (const Node& node : nodes_) {
      const double s = std::sin(node.theta), c = std::cos(node.theta);
      // k.h = a cos(phi) + b with a = sin(theta_k) sin(theta), b = cos(theta_k) cos(theta).
      const double a = sk * s, b = ck * c;
      const double p = positive_phi_integral(a, b);
      spread(pos, node, p * s * node.weight);
      spread(abs, node, (2.0 * p - 2.0 * kPi * b) * s * node.weight);  // |x| = 2 max(0, x) - x
    }
  });
}

}  // namespace facetfit
