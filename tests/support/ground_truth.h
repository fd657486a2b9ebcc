// Accuracy against ground truth: an analytic material written into a MERL table, fitted, and compared
// with the parameters it was made from: a test oracle, not part of the library. The accuracy tests and
// docs/accuracy.md (bench/accuracy_table.cpp) share it through the facetfit_testing library.
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "core/brdf.h"
#include "fit/extract_2d.h"
#include "fit/fit.h"
#include "model/fresnel.h"
#include "model/ndf.h"
#include "model/rotated.h"

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

// Anisotropic ground truth: an analytic NDF with F = 1 and axes turned by `angle_degrees`, its
// back-scattering extracted in 2D (fit/extract_2d.h), principal alphas and angle compared.
struct AnisotropicCase {
  NdfType type = NdfType::ggx;
  double alpha_x = 0.4, alpha_y = 0.15, angle_degrees = 0.0;
  Smith smith = Smith::masking;
};

struct AnisotropicError {
  AnisotropicAlpha fitted;
  double alpha_x_relative = 0.0, alpha_y_relative = 0.0;  // fitted / true - 1
  double angle_degrees = 0.0;                              // fitted - true
  double ndf_l1 = 0.0;  // projected-area weighted relative L1 of D at the grid's nodes (dense input only)
  double eigenvalue = 0.0;
  int iterations = 0;
  std::string problem;
};

// The cases of the tests and of docs/accuracy.md: dense analytic back-scattering (every Smith model,
// GGX and Beckmann, rotated), and through UTIA files (alpha >= 0.2, the bar).
std::vector<AnisotropicCase> dense_anisotropic_cases();
std::vector<AnisotropicCase> utia_anisotropic_cases();

// Where the back-scattering comes from: the analytic model at MERL's theta_h bins; a UTIA file written by
// facetfit's writer and read back (six polar angles); an RGL tensor file written by the tests' writer
// (support/tensor_file.h: 25 x 16 slices) and read back through its evaluation on 90 polar angles.
enum class AnisotropicInput { dense, utia, rgl };

// The files go to `path` (UTIA and RGL inputs).
AnisotropicError measure_anisotropic(const AnisotropicCase& c, const Quadrature2D& quadrature,
                                     AnisotropicInput input = AnisotropicInput::dense, const std::string& path = "");

}  // namespace facetfit
