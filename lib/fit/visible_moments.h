// The directional albedo of GGX lobes as the closure fit needs it (fit/closure_fit.cpp), many times a
// solve: from a table of the moments of the lobe's visible normals at a fixed set of views,
//   M_e(o, alpha_x, alpha_y) = (1/N) sum_k (1 - o.h_k)^e G2(o, i_k) / G1(o),
// h_k the visible normals of GGX (alpha_x along the view's azimuth, alpha_y across it) seen from o at N = 256
// fixed points of the disk (model/ggx_visible.h: a golden-angle spiral), i_k = o reflected about h_k, G2
// height-correlated (0 where i_k falls below the horizon). The sum is smooth in the alphas because the points
// are fixed. A lobe of Fresnel F(mu) = sum_j c_j (1 - mu)^(e_j) returns rho(o) = sum_j c_j M_(e_j)(o, ...):
// Schlick's and the generalized Schlick's forms need e in {0, 5} or {0, e}, F82-tint's {0, 5, 6, 7}. An
// isotropic lobe is alpha_x = alpha_y; a view-aligned closure lobe (model/closures.h) has its own alpha_y at
// each view.
//
// The table holds M at 32 intervals of each log alpha over [log 1e-3, 0] by 40 intervals of t = sqrt(e) over
// [0, sqrt(10)] (e is a power of 1 - mu < 1: the moments fall fastest at small e, where sqrt spaces the
// nodes closest), with one node beyond each end, and is read by Catmull-Rom splines in the three variables:
// its derivatives are continuous, as the solver's steps need. A view's cells of (alpha_x, alpha_y) nodes are
// summed when a read first needs them (a fit visits a few dozen of the 1,225), once, whichever thread asks.
// It agrees with the direct sum to 2e-4 of the albedo of F = 1 (tests/fit/test_closures.cpp).
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

namespace facetfit {

class VisibleMoments {
 public:
  static constexpr double kMinAlpha = 1e-3, kMaxAlpha = 1.0, kMaxExponent = 10.0;

  // The table at views cos theta_o = cos_o[j]. Tables are kept for the process by their views: the fits
  // of a batch share one.
  static std::shared_ptr<const VisibleMoments> at_views(const std::vector<double>& cos_o);

  // M_e at view `view` and its derivatives in log alpha_x, log alpha_y and e (e in [0, kMaxExponent]; the
  // alphas and e are clamped to the table's ranges).
  struct Moment {
    double value = 0.0, d_log_alpha_x = 0.0, d_log_alpha_y = 0.0, d_exponent = 0.0;
    double d_log_alpha() const { return d_log_alpha_x + d_log_alpha_y; }  // of an isotropic lobe
  };
  Moment at(std::size_t view, double log_alpha_x, double log_alpha_y, double exponent) const;
  Moment at(std::size_t view, double log_alpha, double exponent) const { return at(view, log_alpha, log_alpha, exponent); }

  // The direct sum M_e(o, alpha_x, alpha_y) at cos theta_o, as the table's nodes hold it.
  static double sum(double cos_o, double alpha_x, double alpha_y, double exponent);

  // Calls visit(o.h, G2(o, i) / G1(o) / N) for the fixed visible normals of GGX (alpha_x, alpha_y) seen from
  // cos theta_o along the x axis that reflect o above the horizon.
  static void for_each_visible_normal(double cos_o, double alpha_x, double alpha_y, const std::function<void(double mu, double ratio)>& visit);

  explicit VisibleMoments(std::vector<double> cos_o);
  ~VisibleMoments();

 private:
  static constexpr int kPoints = 256, kAlphaIntervals = 32, kRootIntervals = 40;
  static constexpr int kAlphaNodes = kAlphaIntervals + 3, kRootNodes = kRootIntervals + 3;  // one beyond each end
  // The cell (view, alpha_x node, alpha_y node): its kRootNodes moments, summed on first use.
  const double* cell(std::size_t view, int x, int y) const;
  std::vector<double> cos_o_;
  mutable std::vector<double> table_;  // [view][alpha_x node][alpha_y node][root node]
  struct Filled;                       // one std::once_flag per cell
  std::unique_ptr<Filled> filled_;
};

}  // namespace facetfit
