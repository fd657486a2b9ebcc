// Bounded nonlinear least squares for the parametric fits' problems: 8 to 14 unknowns in a few parameter
// blocks over ~10^4 residuals, given as Ceres cost functions with analytic Jacobians.
//
// Ceres solves them too, but spends three quarters of such a solve on its per-entry Jacobian bookkeeping
// (each block's Jacobian invalidated, written, validated and copied into the dense matrix: docs/extraction.md,
// "Time"). Here the same cost functions are evaluated into one buffer per residual block and J^T J, J^T r
// accumulated at once (n x n, n <= 14), and the step is Levenberg-Marquardt's,
//   (J^T J + mu diag(J^T J)) delta = -J^T r,
// projected onto the bounds, mu updated by the gain ratio (Nielsen's rule), stopping when the cost moves by
// less than `function_tolerance` of itself, as Ceres's function tolerance does.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

namespace ceres {
class CostFunction;
}

namespace facetfit {

class SmallProblem {
 public:
  SmallProblem();
  ~SmallProblem();
  SmallProblem(const SmallProblem&) = delete;
  SmallProblem& operator=(const SmallProblem&) = delete;

  // The residual block `cost` (the problem takes it) over `blocks` (each of the size the cost function declares). A block is
  // known by its address; the first use of an address adds it, unbounded and variable.
  void AddResidualBlock(ceres::CostFunction* cost, std::nullptr_t, std::vector<double*> blocks);
  template <class... Blocks>
  void AddResidualBlock(ceres::CostFunction* cost, std::nullptr_t, Blocks*... blocks) {
    AddResidualBlock(cost, nullptr, std::vector<double*>{blocks...});
  }
  void SetParameterLowerBound(double* block, int index, double bound);
  void SetParameterUpperBound(double* block, int index, double bound);
  void SetParameterBlockConstant(double* block);

  struct Summary {
    int iterations = 0;         // accepted steps
    int evaluations = 0;        // of the residuals, with or without the Jacobian
    double initial_cost = 0.0;  // 1/2 sum r^2
    double final_cost = 0.0;
  };
  // Moves the blocks' values (clamped into their bounds first) toward a minimum of 1/2 sum r^2.
  Summary Solve(int max_iterations, double function_tolerance = 1e-6);

 private:
  struct Block {
    double* values;
    int size;
    bool constant = false;
    std::vector<double> lower, upper;
    int offset = -1;  // in the vector of unknowns; -1 when constant
  };
  struct Residuals {
    std::unique_ptr<ceres::CostFunction> cost;
    std::vector<int> blocks;  // indices into blocks_
  };
  Block& block_of(double* values, int size = -1);

  std::vector<Block> blocks_;
  std::vector<Residuals> residuals_;
};

}  // namespace facetfit
