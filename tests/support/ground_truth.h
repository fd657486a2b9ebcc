// Accuracy against ground truth: an analytic material written into a MERL table, fitted, and compared
// with the parameters it was made from: a test oracle, not part of the library. The accuracy tests and
// docs/accuracy.md (bench/accuracy_table.cpp) share it through the facetfit_testing library.
#pragma once

#include <string>
#include <vector>

#include "fit/fit.h"
#include "model/fresnel.h"
#include "model/ndf.h"

namespace facetfit {

struct GroundTruthCase {
  NdfType type = NdfType::ggx;
  double alpha = 0.2;
  Smith smith = Smith::correlated;  // the model the data is made with
  Fresnel fresnel = Fresnel::one();
};

struct GroundTruthError {
  double alpha = 0.0;          // fitted alpha of the case's NDF type
  double alpha_relative = 0.0; // fitted / true - 1
  double ndf_l1 = 0.0;         // relative L1 (projected-area weighted) of the tabulated D against the true D
  double fresnel_abs = 0.0;    // max |F_fit - F_true| over channels and theta_d <= 80 degrees
  int iterations = 0;
  double residual = 0.0;
  std::string problem;
};

// The grid: GGX and Beckmann, alpha in {0.02 ... 1.0}, each Smith model, gold Fresnel.
std::vector<GroundTruthCase> standard_ground_truth_cases();

// Tabulates the case into a MERL table (through `merl_path` on disk when not empty, exercising the
// writer and reader) and fits it with `fitter`.
GroundTruthError measure_ground_truth(const GroundTruthCase& c, const Fitter& fitter, const std::string& merl_path = "");

}  // namespace facetfit
