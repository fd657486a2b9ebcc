// Bounded nonlinear least squares for the fits' problems of a few unknowns over many residuals, given as
// Ceres cost functions: the parametric fits (8 to 14 unknowns, ~10^4 residuals) and the tabulated
// lobe's refinement (~100 to 400 unknowns, each residual touching ~10 of them).
//
// Ceres solved them before, and spent three quarters of a parametric solve on its per-entry Jacobian
// bookkeeping (each block's Jacobian invalidated, written, validated and copied: docs/extraction.md,
// "Time"). Here the cost functions are evaluated into one buffer per residual block, whose J^T J and
// J^T r are added into the n x n normal equations over the block's own unknowns, and the step is
// Levenberg-Marquardt's,
//   (J^T J + mu diag(J^T J)) delta = -J^T r,
// with the unknowns that sit on a bound the gradient pushes against held there (an active set), the rest
// projected onto the bounds; mu follows the gain ratio (Nielsen's rule), and the solve stops when an
// accepted step moves the cost by less than `function_tolerance` of itself, as Ceres's function
// tolerance does. Dense: meant for n up to a few hundred.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

namespace ceres {
class CostFunction;
}

namespace facetfit {

// The largest relative difference between `cost`'s Jacobian and central differences at `blocks` (which it
// moves and restores): the check of the fits' hand-written derivatives (tests/fit/test_refine.cpp).
double jacobian_error(const ceres::CostFunction& cost, const std::vector<double*>& blocks);

class SmallProblem {
 public:
  SmallProblem();
  ~SmallProblem();
  SmallProblem(const SmallProblem&) = delete;
  SmallProblem& operator=(const SmallProblem&) = delete;

  // The residual block `cost` (the problem takes it) over `blocks` (each of the size the cost function declares). A block is
  // known by its address; the first use of an address adds it, unbounded and variable.
  void add_residual_block(ceres::CostFunction* cost, std::vector<double*> blocks);
  template <class... Blocks>
  void add_residual_block(ceres::CostFunction* cost, Blocks*... blocks) {
    add_residual_block(cost, std::vector<double*>{blocks...});
  }
  void set_lower_bound(double* block, int index, double bound);
  void set_upper_bound(double* block, int index, double bound);
  void set_constant(double* block);

  struct Summary {
    int iterations = 0;       // accepted steps
    double final_cost = 0.0;  // 1/2 sum r^2
  };
  // Moves the blocks' values (clamped into their bounds first) toward a minimum of 1/2 sum r^2.
  Summary solve(int max_iterations, double function_tolerance = 1e-6);

  // What the problem holds, as solve's steps (small_problem.cpp) read it.
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

 private:
  // The index of the block at `values`, added (of `size`) at its first use.
  std::size_t block_of(double* values, int size = -1);

  std::vector<Block> blocks_;
  std::vector<Residuals> residuals_;
};

}  // namespace facetfit
