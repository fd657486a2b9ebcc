#include "fit/small_problem.h"

#include <ceres/cost_function.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>

namespace facetfit {

double jacobian_error(const ceres::CostFunction& cost, const std::vector<double*>& blocks) {
  const std::size_t n = std::size_t(cost.num_residuals()), count = blocks.size();
  const std::vector<int32_t>& sizes = cost.parameter_block_sizes();
  std::vector<std::vector<double>> jacobian(count);
  std::vector<double*> jacobian_ptrs(count);
  for (std::size_t b = 0; b < count; ++b) {
    jacobian[b].resize(n * std::size_t(sizes[b]));
    jacobian_ptrs[b] = jacobian[b].data();
  }
  std::vector<double> r(n), plus(n), minus(n);
  cost.Evaluate(blocks.data(), r.data(), jacobian_ptrs.data());
  double scale = 0.0, worst = 0.0;
  for (const std::vector<double>& j : jacobian)
    for (double v : j) scale = std::max(scale, std::abs(v));
  for (std::size_t b = 0; b < count; ++b) {
    const std::size_t size = std::size_t(sizes[b]);
    for (std::size_t e = 0; e < size; ++e) {
      double& x = blocks[b][e];
      const double x0 = x, h = 1e-6 * std::max(1.0, std::abs(x0));
      x = x0 + h;
      cost.Evaluate(blocks.data(), plus.data(), nullptr);
      x = x0 - h;
      cost.Evaluate(blocks.data(), minus.data(), nullptr);
      x = x0;
      for (std::size_t k = 0; k < n; ++k) {
        const double numeric = (plus[k] - minus[k]) / (2.0 * h), analytic = jacobian[b][k * size + e];
        // Relative, with a floor below which central differences are rounding noise.
        worst = std::max(worst, std::abs(analytic - numeric) / (std::abs(numeric) + 1e-3 * scale + 1e-8));
      }
    }
  }
  return worst;
}

SmallProblem::SmallProblem() = default;
SmallProblem::~SmallProblem() = default;

std::size_t SmallProblem::block_of(double* values, int size) {
  for (std::size_t b = 0; b < blocks_.size(); ++b)
    if (blocks_[b].values == values) return b;
  const double inf = std::numeric_limits<double>::infinity();
  blocks_.push_back(Block{values, size, false, std::vector<double>(std::size_t(size), -inf), std::vector<double>(std::size_t(size), inf)});
  return blocks_.size() - 1;
}

void SmallProblem::add_residual_block(ceres::CostFunction* cost, std::vector<double*> blocks) {
  Residuals r{std::unique_ptr<ceres::CostFunction>(cost), {}};
  const std::vector<int32_t>& sizes = cost->parameter_block_sizes();
  for (std::size_t k = 0; k < blocks.size(); ++k) r.blocks.push_back(int(block_of(blocks[k], sizes[k])));
  residuals_.push_back(std::move(r));
}

void SmallProblem::set_lower_bound(double* block, int index, double bound) { blocks_[block_of(block)].lower[std::size_t(index)] = bound; }
void SmallProblem::set_upper_bound(double* block, int index, double bound) { blocks_[block_of(block)].upper[std::size_t(index)] = bound; }
void SmallProblem::set_constant(double* block) { blocks_[block_of(block)].constant = true; }

namespace {

using Vector = Eigen::VectorXd;
using Matrix = Eigen::MatrixXd;

using Block = SmallProblem::Block;
using Residuals = SmallProblem::Residuals;

// The unknowns of the variable blocks, clamped into their bounds, and those bounds.
void gather_unknowns(const std::vector<Block>& blocks, Vector& x, Vector& lower, Vector& upper) {
  for (const Block& b : blocks)
    for (int j = 0; j < b.size && b.offset >= 0; ++j) {
      lower[b.offset + j] = b.lower[std::size_t(j)], upper[b.offset + j] = b.upper[std::size_t(j)];
      x[b.offset + j] = std::clamp(b.values[j], lower[b.offset + j], upper[b.offset + j]);
    }
}

// The unknowns `v` written back into the variable blocks' values.
void scatter(const std::vector<Block>& blocks, const Vector& v) {
  for (const Block& b : blocks)
    for (int j = 0; j < b.size && b.offset >= 0; ++j) b.values[j] = v[b.offset + j];
}

// What one evaluation of the residual blocks reuses from the last: a block's residuals and Jacobians, and
// its rows of J over the unknowns it touches.
struct Workspace {
  std::vector<double> residual, jacobian_buffer;
  std::vector<double*> jacobians;
  std::vector<const double*> parameters;
  std::vector<int> columns;
  Matrix rows, local;
  Vector local_r;
};

// The arguments of a residual block of `m` residuals over `used` blocks: their values, and with
// `with_jacobians` a slice of one buffer for each variable block's Jacobian (nullptr for a constant one).
void point_at_blocks(const std::vector<Block>& blocks, const std::vector<int>& used, int m, bool with_jacobians, Workspace& w) {
  w.residual.resize(std::size_t(m));
  w.parameters.clear();
  w.jacobians.clear();
  std::size_t size = 0;
  for (int b : used) size += std::size_t(m) * std::size_t(blocks[std::size_t(b)].size);
  w.jacobian_buffer.resize(size);
  size = 0;
  for (int b : used) {
    const Block& block = blocks[std::size_t(b)];
    w.parameters.push_back(block.values);
    w.jacobians.push_back(with_jacobians && !block.constant ? w.jacobian_buffer.data() + size : nullptr);
    size += std::size_t(m) * std::size_t(block.size);
  }
}

// This block's rows of J over the unknowns it touches (a few of the n: the scatter keeps the
// accumulation sparse), and their columns among the n.
void gather_rows(const std::vector<Block>& blocks, const std::vector<int>& used, int m, Workspace& w) {
  w.columns.clear();
  for (std::size_t k = 0; k < used.size(); ++k)
    if (w.jacobians[k]) {
      const Block& block = blocks[std::size_t(used[k])];
      for (int j = 0; j < block.size; ++j) w.columns.push_back(block.offset + j);
    }
  w.rows.resize(m, Eigen::Index(w.columns.size()));
  Eigen::Index column = 0;
  for (std::size_t k = 0; k < used.size(); ++k) {
    if (!w.jacobians[k]) continue;
    const int size = blocks[std::size_t(used[k])].size;
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < size; ++j) w.rows(i, column + j) = w.jacobians[k][std::size_t(i * size + j)];
    column += size;
  }
}

// The gathered rows' J^T J and J^T r, added into the normal equations.
void add_to_normal_equations(Workspace& w, int m, Matrix& jtj, Vector& jtr) {
  // Coefficient-wise for a few unknowns, where GEMM's packing costs more; GEMM past 20 (the closure fit's
  // 13 to 29), where its blocking wins (a symmetric rank update, half the products, is slower).
  if (w.columns.size() < 20)
    w.local.noalias() = w.rows.transpose().lazyProduct(w.rows);
  else
    w.local.noalias() = w.rows.transpose() * w.rows;
  w.local_r.noalias() = w.rows.transpose() * Eigen::Map<const Vector>(w.residual.data(), m);
  for (std::size_t a = 0; a < w.columns.size(); ++a) {
    jtr[w.columns[a]] += w.local_r[Eigen::Index(a)];
    for (std::size_t b = 0; b < w.columns.size(); ++b) jtj(w.columns[a], w.columns[b]) += w.local(Eigen::Index(a), Eigen::Index(b));
  }
}

// 1/2 sum r^2 at the blocks' values, and J^T J, J^T r (over the n unknowns) when asked; NaN when a cost
// function fails or yields a non-finite value.
double evaluate_residuals(const std::vector<Block>& blocks, const std::vector<Residuals>& residuals, int n, Matrix* jtj, Vector* jtr,
                          Workspace& w) {
  if (jtj) jtj->setZero(n, n), jtr->setZero(n);
  double cost = 0.0;
  for (const Residuals& r : residuals) {
    const int m = r.cost->num_residuals();
    point_at_blocks(blocks, r.blocks, m, jtj != nullptr, w);
    if (!r.cost->Evaluate(w.parameters.data(), w.residual.data(), jtj ? w.jacobians.data() : nullptr))
      return std::numeric_limits<double>::quiet_NaN();
    for (double e : w.residual) cost += 0.5 * e * e;
    if (!jtj) continue;
    gather_rows(blocks, r.blocks, m, w);
    add_to_normal_equations(w, m, *jtj, *jtr);
  }
  return std::isfinite(cost) ? cost : std::numeric_limits<double>::quiet_NaN();
}

// Unknowns on a bound that the gradient pushes outward stay there this iteration (an active set):
// left in the system, the step would spend itself against the bound and its projection could
// even raise the cost the quadratic model predicts. Their entries of `rhs` are zeroed.
std::vector<bool> active_set(const Vector& x, const Vector& lower, const Vector& upper, const Vector& jtr, Vector& rhs) {
  const Eigen::Index n = x.size();
  std::vector<bool> active(static_cast<std::size_t>(n), false);
  for (Eigen::Index k = 0; k < n; ++k) {
    active[std::size_t(k)] = (x[k] <= lower[k] && jtr[k] > 0.0) || (x[k] >= upper[k] && jtr[k] < 0.0);
    if (active[std::size_t(k)]) rhs[k] = 0.0;
  }
  return active;
}

// The damped step from x, (J^T J + mu D) delta = rhs with the active unknowns held, projected onto the bounds.
Vector bounded_step(const Matrix& jtj, const Vector& d, double mu, const std::vector<bool>& active, const Vector& rhs,
                    const Vector& x, const Vector& lower, const Vector& upper) {
  Matrix m = jtj;
  m.diagonal() += mu * d;
  for (Eigen::Index k = 0; k < x.size(); ++k)
    if (active[std::size_t(k)]) m.row(k).setZero(), m.col(k).setZero(), m(k, k) = 1.0;
  return (m.ldlt().solve(rhs) + x).cwiseMax(lower).cwiseMin(upper) - x;
}

// Levenberg-Marquardt from x, where `evaluate(v, &jtj, &jtr)` gave `cost`, `jtj` and `jtr`, which follow
// the accepted steps; returns how many were accepted.
template <class Evaluate>
int levenberg_marquardt(const Evaluate& evaluate, const Vector& lower, const Vector& upper, int max_iterations,
                        double function_tolerance, Vector& x, double& cost, Matrix& jtj, Vector& jtr) {
  int accepted_steps = 0;
  Matrix trial_jtj;
  Vector trial_jtr;
  double mu = 1e-4, nu = 2.0;  // Ceres's start: a trust region of radius 1e4
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    bool accepted = false, converged = false;
    // Marquardt's scaling, its diagonal clamped as Ceres clamps it, so that an unknown the data do not
    // see still gets a finite step.
    const Vector d = jtj.diagonal().cwiseMax(1e-6).cwiseMin(1e32);
    Vector rhs = -jtr;
    const std::vector<bool> active = active_set(x, lower, upper, jtr, rhs);
    for (int attempt = 0; attempt < 20 && !accepted; ++attempt) {
      const Vector step = bounded_step(jtj, d, mu, active, rhs, x, lower, upper);
      const double predicted = -(jtr.dot(step) + 0.5 * step.dot(jtj * step));
      const Vector trial = x + step;
      // The trial's J^T J and J^T r with its cost: most steps are accepted, and the residuals are then
      // evaluated once rather than twice.
      const double trial_cost = evaluate(trial, &trial_jtj, &trial_jtr);
      if (std::isfinite(trial_cost) && trial_cost < cost && predicted > 0.0) {
        const double rho = (cost - trial_cost) / predicted;
        mu *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
        nu = 2.0;
        converged = cost - trial_cost <= function_tolerance * cost;
        x = trial;
        cost = trial_cost;
        jtj.swap(trial_jtj), jtr.swap(trial_jtr);
        accepted = true;
        ++accepted_steps;
      } else {
        mu *= nu;
        nu *= 2.0;
      }
    }
    if (!accepted || converged) break;
  }
  return accepted_steps;
}

}  // namespace

SmallProblem::Summary SmallProblem::solve(int max_iterations, double function_tolerance) {
  Summary summary;
  int n = 0;
  for (Block& b : blocks_) b.offset = b.constant ? -1 : (n += b.size) - b.size;
  if (n == 0 || residuals_.empty() || max_iterations <= 0) return summary;

  Vector x(n), lower(n), upper(n);
  gather_unknowns(blocks_, x, lower, upper);
  Workspace workspace;
  const auto evaluate = [&](const Vector& v, Matrix* jtj, Vector* jtr) {
    scatter(blocks_, v);
    return evaluate_residuals(blocks_, residuals_, n, jtj, jtr, workspace);
  };
  Matrix jtj;
  Vector jtr;
  double cost = evaluate(x, &jtj, &jtr);
  summary.final_cost = cost;
  if (!std::isfinite(cost)) {
    scatter(blocks_, x);
    return summary;
  }
  summary.iterations = levenberg_marquardt(evaluate, lower, upper, max_iterations, function_tolerance, x, cost, jtj, jtr);
  scatter(blocks_, x);
  summary.final_cost = cost;
  return summary;
}

}  // namespace facetfit
