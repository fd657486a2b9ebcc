#include "fit/refine.h"

#include <ceres/ceres.h>

#include <cmath>
#include <algorithm>
#include <array>
#include <map>
#include <memory>

namespace facetfit {

namespace {

// The D nodes whose weighted sum is D at one theta (the spline's stencil, duplicates merged).
struct NodeWeights {
  std::vector<int> node;
  std::vector<double> weight;
};

NodeWeights node_weights(const ThetaGrid& grid, double theta) {
  int j;
  double t;
  grid.locate(theta, &j, &t);
  const ThetaGrid::Stencil s = grid.stencil(j, t);
  std::map<int, double> merged;
  for (int q = 0; q < 4; ++q)
    if (s.weight[q] != 0.0) merged[s.index[q]] += s.weight[q];
  NodeWeights w;
  for (const auto& [n, x] : merged)
    if (std::abs(x) > 1e-12) w.node.push_back(n), w.weight.push_back(x);
  return w;
}

// The residuals of one (theta_h, theta_d) row: 3 per bin. Parameter blocks: body (3), the row's
// Fresnel entry (3), then its D nodes (1 each). `g` holds G2 / (4 cos_i cos_o) per bin for this pass.
class RowCost final : public ceres::CostFunction {
 public:
  RowCost(const MeasuredBins& bins, const MeasuredBins::Row& row, const std::vector<double>& g,
          const std::vector<double>& coat, NodeWeights nodes)
      : bins_(bins), row_(row), g_(g), coat_(coat), nodes_(std::move(nodes)) {
    set_num_residuals(int(3 * (row.end - row.begin)));
    mutable_parameter_block_sizes()->push_back(3);
    mutable_parameter_block_sizes()->push_back(3);
    for (std::size_t q = 0; q < nodes_.node.size(); ++q) mutable_parameter_block_sizes()->push_back(1);
  }

  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    const double* body = p[0];
    const double* fresnel = p[1];
    double d = 0.0;
    for (std::size_t q = 0; q < nodes_.node.size(); ++q) d += nodes_.weight[q] * p[2 + q][0];
    const std::size_t n = row_.end - row_.begin;
    for (std::size_t b = 0; b < n; ++b) {
      const std::size_t k = row_.begin + b;
      const double s = std::sqrt(bins_.weight[k]), c = bins_.cosine[k], g = g_[k];
      for (int ch = 0; ch < 3; ++ch) {
        const std::size_t r = 3 * b + std::size_t(ch);
        const bool valid = bins_.valid[k] >> ch & 1u;
        const double m = body[ch] * kInvPi + fresnel[ch] * d * g + coat_[k];
        const MetricResidual res = valid ? metric_residual(m, c, bins_.lightness[k][ch]) : MetricResidual{};
        residuals[r] = s * res.value;
        if (!jacobians) continue;
        const double dm = s * res.slope;  // d/dm of the residual: the chain rule for every parameter below
        if (jacobians[0])
          for (int e = 0; e < 3; ++e) jacobians[0][3 * r + std::size_t(e)] = e == ch ? dm * kInvPi : 0.0;
        if (jacobians[1])
          for (int e = 0; e < 3; ++e) jacobians[1][3 * r + std::size_t(e)] = e == ch ? dm * d * g : 0.0;
        for (std::size_t q = 0; q < nodes_.node.size(); ++q)
          if (jacobians[2 + q]) jacobians[2 + q][r] = dm * fresnel[ch] * g * nodes_.weight[q];
      }
    }
    return true;
  }

 private:
  const MeasuredBins& bins_;
  const MeasuredBins::Row& row_;
  const std::vector<double>& g_;
  const std::vector<double>& coat_;
  NodeWeights nodes_;
};

// weight (sum_j area_j D_j - 1): keeps the NDF normalized, which fixes the scale shared by D and F.
class NormalizationCost final : public ceres::CostFunction {
 public:
  NormalizationCost(const std::vector<double>& area, double weight) : area_(area), weight_(weight) {
    set_num_residuals(1);
    for (std::size_t j = 0; j < area.size(); ++j) mutable_parameter_block_sizes()->push_back(1);
  }
  bool Evaluate(double const* const* p, double* residuals, double** jacobians) const override {
    double s = 0.0;
    for (std::size_t j = 0; j < area_.size(); ++j) s += area_[j] * p[j][0];
    residuals[0] = weight_ * (s - 1.0);
    if (jacobians)
      for (std::size_t j = 0; j < area_.size(); ++j)
        if (jacobians[j]) jacobians[j][0] = weight_ * area_[j];
    return true;
  }

 private:
  const std::vector<double>& area_;
  double weight_;
};

// weight (x_{j-1} - 2 x_j + x_{j+1}) per component of N: the Fresnel curve's channels (N = 3), or an
// NDF node (N = 1, the weight already divided by the node's scale: a relative second difference).
template <int N>
struct SecondDifference {
  double weight;
  template <class T>
  bool operator()(const T* a, const T* b, const T* c, T* r) const {
    for (int k = 0; k < N; ++k) r[k] = weight * (a[k] - 2.0 * b[k] + c[k]);
    return true;
  }
};

}  // namespace

double normalize_ndf(TabulatedNdf& ndf, const Quadrature& quad) {
  const std::vector<double>& area = quad.projected_area();
  double s = 0.0;
  for (std::size_t j = 0; j < area.size(); ++j) s += area[j] * ndf.ndf[j];
  if (s > 0.0)
    for (double& v : ndf.ndf) v /= s;
  ndf.sigma.resize(ndf.ndf.size());
  for (int k = 0; k < quad.size(); ++k) {
    const double* row = quad.positive_row(k);
    double sigma = 0.0;
    for (std::size_t j = 0; j < ndf.ndf.size(); ++j) sigma += row[j] * ndf.ndf[j];
    ndf.sigma[std::size_t(k)] = sigma;
  }
  return s;
}

LobeFit refine_lobe(const MeasuredBins& bins, const Quadrature& quad, Smith smith, const LobeFit& start,
                    const RefineOptions& options) {
  LobeFit fit = start;
  if (bins.size() == 0) return fit;
  const ThetaGrid& grid = quad.grid();
  normalize_ndf(fit.ndf, quad);
  std::vector<double> d = fit.ndf.ndf;
  std::vector<double> body = {fit.body.r, fit.body.g, fit.body.b};
  std::vector<std::array<double, 3>> fresnel(FresnelCurve::kSize);
  for (int j = 0; j < FresnelCurve::kSize; ++j)
    for (int c = 0; c < 3; ++c) fresnel[std::size_t(j)][std::size_t(c)] = clamp(fit.fresnel.value[std::size_t(j)][c], 0.0, 1.0);
  std::vector<double> g(bins.size()), coat(bins.size());
  for (std::size_t k = 0; k < bins.size(); ++k) coat[k] = start.coat.eval(bins.o[k], bins.i[k]);
  std::vector<NodeWeights> row_nodes;
  row_nodes.reserve(bins.rows.size());
  for (const MeasuredBins::Row& row : bins.rows) row_nodes.push_back(node_weights(grid, MerlTable::theta_h(row.theta_h)));
  // The Fresnel unknowns are the entries at the theta_d the bins sample (the knots); the entries between
  // them are linear in between, those past the last knot equal it. The entries no bin sees carry no
  // information of their own, and fewer unknowns make a faster solve.
  std::vector<int> knots;
  for (const MeasuredBins::Row& row : bins.rows) knots.push_back(row.theta_d);
  std::sort(knots.begin(), knots.end());
  knots.erase(std::unique(knots.begin(), knots.end()), knots.end());
  // The two knots bracketing entry position x and their weights.
  const auto bracket = [&knots](double x, int e[2], double w[2]) {
    const auto above = std::upper_bound(knots.begin(), knots.end(), x);
    if (above == knots.begin() || above == knots.end()) {
      e[0] = e[1] = above == knots.begin() ? knots.front() : knots.back();
      w[0] = 1.0, w[1] = 0.0;
      return;
    }
    e[0] = *(above - 1), e[1] = *above;
    w[1] = (x - e[0]) / double(e[1] - e[0]), w[0] = 1.0 - w[1];
  };

  for (int pass = 0; pass < options.passes; ++pass) {
    // G2 / (4 cos_i cos_o) of the current NDF, held for this pass.
    const G1Table g1(fit.ndf);
    for (std::size_t k = 0; k < bins.size(); ++k) {
      const double mi = bins.i[k].z, mo = bins.o[k].z;
      g[k] = smith_g2_from_g1(smith, g1(mi), g1(mo)) / (4.0 * mi * mo);
    }
    ceres::Problem::Options problem_options;
    problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    for (std::size_t r = 0; r < bins.rows.size(); ++r) {
      const MeasuredBins::Row& row = bins.rows[r];
      std::vector<double*> blocks{body.data(), fresnel[std::size_t(row.theta_d)].data()};
      for (int n : row_nodes[r].node) blocks.push_back(&d[std::size_t(n)]);
      problem.AddResidualBlock(new RowCost(bins, row, g, coat, row_nodes[r]), nullptr, blocks);
    }
    std::vector<double*> all_nodes;
    for (double& v : d) all_nodes.push_back(&v);
    problem.AddResidualBlock(new NormalizationCost(quad.projected_area(), 10.0), nullptr, all_nodes);
    for (std::size_t k = 1; k + 1 < knots.size(); ++k)
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<SecondDifference<3>, 3, 3, 3, 3>(new SecondDifference<3>{options.fresnel_smoothness}),
          nullptr, fresnel[std::size_t(knots[k - 1])].data(), fresnel[std::size_t(knots[k])].data(), fresnel[std::size_t(knots[k + 1])].data());
    for (std::size_t j = 1; j + 1 < d.size(); ++j) {
      const double scale = std::max(d[j], 1e-3 * d[0] + 1e-6);
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<SecondDifference<1>, 1, 1, 1, 1>(
                                   new SecondDifference<1>{options.ndf_smoothness / scale}),
                               nullptr, &d[j - 1], &d[j], &d[j + 1]);
    }
    // Bounds, not a clamp afterwards: left free, the solve trades negative nodes against each other.
    for (int c = 0; c < 3; ++c) problem.SetParameterLowerBound(body.data(), c, 0.0);
    // A Fresnel factor is a reflectance: in [0, 1] (above 1 the fit would trade the NDF's scale for it).
    for (int j : knots)
      for (int c = 0; c < 3; ++c)
        problem.SetParameterLowerBound(fresnel[std::size_t(j)].data(), c, 0.0), problem.SetParameterUpperBound(fresnel[std::size_t(j)].data(), c, 1.0);
    for (double& v : d) problem.SetParameterLowerBound(&v, 0, 0.0);

    ceres::Solver::Options solver;
    solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    solver.max_num_iterations = options.max_iterations;
    solver.num_threads = options.threads;
    solver.function_tolerance = 1e-7;
    solver.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);

    fit.ndf.ndf = d;
    const double area = normalize_ndf(fit.ndf, quad);  // F D stays what the solve found
    d = fit.ndf.ndf;
    for (auto& f : fresnel)
      for (double& v : f) v = std::min(v * area, 1.0);
  }
  fit.body = Rgb(body[0], body[1], body[2]);
  for (int j = 0; j < FresnelCurve::kSize; ++j) {
    int e[2];
    double w[2];
    bracket(j, e, w);
    for (int c = 0; c < 3; ++c)
      fit.fresnel.value[std::size_t(j)][c] = w[0] * fresnel[std::size_t(e[0])][std::size_t(c)] + w[1] * fresnel[std::size_t(e[1])][std::size_t(c)];
  }
  return fit;
}

}  // namespace facetfit
