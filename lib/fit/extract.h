// Extraction of the NDF by power iteration (Dupuy et al. 2015), consistent with a chosen Smith model.
//
// Back-scattering (i = o = k, so h = k and theta_d = 0) of a microfacet BRDF gives
//   f(k, k) = F0 D(k) G2(k, k) / (4 cos^2 theta_k).
// With G1(k) = cos theta_k / sigma(k), each Smith model turns this into an equation for D alone:
//   masking     G2(k,k) = G1(k):          F0 D(k) = 4 cos theta_k f(k,k) integral max(0, k.h) D(h) dw_h
//   correlated  G2(k,k) = 1/(1 + 2 Lambda): F0 D(k) = 4 cos theta_k f(k,k) integral |k.h| D(h) dw_h
//   separable   G2(k,k) = G1(k)^2:        F0 D(k) = 4 f(k,k) sigma(k)^2
// The first two are linear eigenproblems with non-negative kernels: D is the dominant eigenvector
// (Perron-Frobenius) and F0 its eigenvalue. The third is a non-linear fixed point, homogeneous of degree
// two, solved by the same normalized iteration. Derivations: docs/extraction.md.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "fit/quadrature.h"
#include "model/tabulated_ndf.h"
#include "model/smith.h"

namespace facetfit {

// f(k, k) measured at polar angles theta (increasing, any spacing), e.g. at MERL's theta_h bins.
struct Backscatter {
  std::vector<double> theta;
  std::vector<double> value;
};

struct ExtractOptions {
  Smith smith = Smith::correlated;
  double tolerance = 1e-10;  // on the relative L1 change of D between two iterations
  int max_iterations = 1000;
};

// How a power iteration ended.
struct PowerIteration {
  double eigenvalue = 0.0;  // the back-scattering estimate of F0 (luminance)
  int iterations = 0;
  double residual = 0.0;    // relative L1 change of D in the last iteration
  bool converged = false;
  std::string problem;      // empty when D is meaningful; otherwise why not
};

struct Extraction : PowerIteration {
  TabulatedNdf ndf;
};

// The normalized power iteration of every extraction, on D over any set of cells (theta nodes, or theta
// nodes x azimuthal bins) with q the kernel factor per cell and area_weight the cells' projected-area
// weights: D <- 4 q sigma (masking; correlated with the |k.h| kernel) or 4 q sigma^2 (separable), renormalized
// to unit projected area, until the projected-area L1 change is within the tolerance. apply(absolute, D,
// sigma) computes the kernel's integral per cell. D holds the start on entry and the answer on return.
PowerIteration power_iterate(std::vector<double>& D, const std::vector<double>& q, const std::vector<double>& area_weight,
                             const ExtractOptions& options,
                             const std::function<void(bool absolute, const std::vector<double>& D, std::vector<double>& sigma)>& apply);

Extraction extract_ndf(const Backscatter& backscatter, const Quadrature& quadrature, const ExtractOptions& options);

// The kernel factor q(theta_j) on the grid nodes: f(k, k) cos(theta_k) (masking, correlated) or f(k, k)
// (separable), interpolated from the measurements by a cubic Hermite spline in u.
std::vector<double> kernel_factor(const Backscatter& backscatter, const ThetaGrid& grid, Smith smith);

}  // namespace facetfit
