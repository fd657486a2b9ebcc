// Quadrature of hemispherical integrals of an isotropic D that is piecewise linear in u on a ThetaGrid.
//
// Every integral the extraction needs is linear in the node values D_j, so it is a dot product with
// precomputed weights. The weights depend only on the grid, never on the material: build a Quadrature
// once per resolution and reuse it for every material.
#pragma once

#include <vector>

#include "core/quadrature_rules.h"
#include "model/theta_grid.h"

namespace facetfit {

class Quadrature {
 public:
  // A sample point of the theta integrals: in interval [u_j, u_j+1] at fraction t, with weight in d(theta).
  struct Node {
    int interval;
    double t;
    double theta;
    double weight;
  };

  explicit Quadrature(int resolution, int points_per_interval = 8);

  const ThetaGrid& grid() const { return grid_; }
  int size() const { return grid_.size(); }

  // Row k of the weights of sigma(theta_k) = integral of max(0, k.h) D(h) dw_h.
  const double* positive_row(int k) const { return positive_.data() + std::size_t(k) * size(); }
  // Row k of the weights of integral of |k.h| D(h) dw_h (the height-correlated back-scattering kernel).
  const double* absolute_row(int k) const { return absolute_.data() + std::size_t(k) * size(); }
  // Weights of the projected area, integral of D cos(theta) dw = 1 for a normalized D.
  const std::vector<double>& projected_area() const { return projected_area_; }
  // Weights of E|x~| = integral of |tan(theta) cos(phi)| D cos(theta) dw.
  const std::vector<double>& abs_slope_moment() const { return abs_slope_; }
  // Weights of E[x~^2]. The last interval (up to pi/2) is left out: there the integral diverges for any
  // D that is not zero at the horizon, as for GGX.
  const std::vector<double>& sq_slope_moment() const { return sq_slope_; }
  const std::vector<Node>& nodes() const { return nodes_; }

 private:
  ThetaGrid grid_;
  std::vector<Node> nodes_;
  std::vector<double> positive_, absolute_;
  std::vector<double> projected_area_, abs_slope_, sq_slope_;
};

}  // namespace facetfit
