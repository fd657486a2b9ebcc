// The whole fit of one measured isotropic material: body albedo, NDF, sigma, RGB Fresnel curve; GGX and
// Beckmann fits; the classical baseline.
//
// Steps: the power iteration on back-scattering and the Fresnel pass (Dupuy et al. 2015: the paper's
// method, `Refine::none`), then, by default, the refinement of body + tabulated lobe on the whole
// measurement (fit/refine.h) and the parametric fits in the same metric (fit/parametric_fit.h).
#pragma once

#include <optional>
#include <vector>
#include <string>

#include "fit/closure_fit.h"
#include "fit/extract.h"
#include "fit/extract_2d.h"
#include "fit/fresnel_fit.h"
#include "fit/parametric_fit.h"
#include "fit/quadrature.h"
#include "fit/refine.h"
#include "io/merl.h"
#include "model/tabulated_anisotropic.h"

namespace facetfit {

// The fit's revision: part of the bake cache's key, so that a LUT baked by an earlier revision of the
// same options is baked again rather than served (lut/bake.h). Bump when the same input and options give
// a different fit. 2: an RGL file's refinement reads its two one-sided estimates (fit/measurement.h);
// 3: the parametric fits solved by fit/small_problem.h; 4: the refinement solved to convergence in two
// passes, a UTIA file's isotropic fits on its own nodes; 5: its anisotropic lobes on its node pairs;
// 6: the grazing pairs' soft L1 loss (fit/measurement.h); 7: the tabulated body's Minnaert exponent (model/body.h);
// 8: the closure representation (fit/closure_fit.h); 9: the paper's representations measured too
// (their distances choose the recommended one, fit/recommend.h); 10: closure lobes that follow the view, the
// tabulated lobe matching the albedo, distances judged with the albedo's (fit/measurement.h judged_distance);
// 11: a closure lobe candidate at the strongest lobe's alpha with a falling Fresnel (fit/closure_fit.cpp).
constexpr int kFitRevision = 11;

// The range of FitOptions::resolution. Below 16 intervals the grid misses narrow lobes: the built-in
// aluminium (GGX 0.05) is extracted at alpha 0.030 with 8 and with a negative E|x| with 5 or 6, and
// docs/pareto.md starts at 16.
constexpr int kMinResolution = 16, kMaxResolution = 4096;

struct FitOptions {
  int resolution = 90;  // intervals of the u grid; R + 1 nodes, kMinResolution to kMaxResolution
  Smith smith = Smith::correlated;
  double tolerance = 1e-10;
  int max_iterations = 1000;
  // full: refinement and parametric fits on the whole measurement (fit/refine.h), ~0.6 s of CPU a
  // material; none: the paper's method alone, a few milliseconds.
  enum class Refine { none, full };
  Refine refine = Refine::full;
  // Which point of its bins a MERL file's values stand for, when the input is read (io/merl.h).
  HalfDiffTable::BinPoint merl_bins = HalfDiffTable::BinPoint::start;
  // The closure representation's first lobe: F82-tint, or generalized Schlick like the rest (fit/closure_fit.h).
  ClosureLobe::Fresnel closure_fresnel = ClosureLobe::Fresnel::f82_tint;

  // The paper's method alone (Refine::none), otherwise the defaults.
  static FitOptions paper() {
    FitOptions o;
    o.refine = Refine::none;
    return o;
  }
};

const char* to_string(FitOptions::Refine r);
std::optional<FitOptions::Refine> parse_refine(const std::string& name);
const char* to_string(ClosureLobe::Fresnel f);  // f82, schlick
std::optional<ClosureLobe::Fresnel> parse_closure_fresnel(const std::string& name);

// The 2D extraction (fit/extract_2d.h) of a source that measured back-scattering along azimuths (a
// UTIA file, an anisotropic RGL file): its principal roughness in each family, and its tables, which
// with the paper's Fresnel curve make the anisotropic tabulated lobe (model/tabulated_anisotropic.h).
struct AnisotropicFit {
  AnisotropicAlpha alpha_ggx, alpha_beckmann;  // moment estimates of the 2D NDF (fit/extract_2d.h)
  // Anisotropic GGX and Beckmann lobes with a body (fit/parametric_fit.h): with Refine::full, fitted on the
  // source's measured pairs or half/difference lattice (fit/measurement.h, anisotropic_bins) from the moment
  // estimates and the isotropic fit's body and Fresnel; with Refine::none, or with neither, the moment estimates with the
  // paper's Fresnel at 0 and 82 degrees, no body (error 0: nothing measured).
  AnisotropicParametricFit ggx, beckmann;
  bool refined = false;
  int iterations = 0;
  double residual = 0.0;
  AnisotropicTables tables;
};

struct FitResult {
  Extraction extraction;  // the power iteration: ndf, sigma, eigenvalue, iterations, residual
  LobeFit lobe;           // body + tabulated lobe: the extraction's, refined unless Refine::none
  double alpha_ggx = 0.0;       // moment estimates of the tabulated NDF (E|x~|, sqrt(2 E[x~^2]))
  double alpha_beckmann = 0.0;
  Rgb f0{0.0};   // F(0) of the tabulated lobe's curve
  Rgb f82{0.0};  // F(acos(1/7)), for the F82-tint Fresnel model
  // Parametric fits on the whole measurement (with Refine::none: the moment alphas, no body, f0 and
  // f82 of the curve); lsq is the classical Lambert + GGX + Schlick baseline.
  ParametricFit ggx, beckmann, lsq;
  // The renderers' closures (fit/closure_fit.h): with Refine::full fitted on the whole measurement from the
  // nearer of ggx and beckmann, for an anisotropic source its anisotropic GGX lobe; with Refine::none the
  // ggx moment fit as one lobe (error 0).
  ClosureFit closures;
  // Distance from the measurement (fit/measurement.h) of the paper's pure fit and of `lobe` (each
  // representation's, ParametricFit::error, measured with either Refine).
  double error_extraction = 0.0, error = 0.0;
  Smith smith = Smith::correlated;  // the model the NDF is consistent with
  bool refined = false;             // Refine::full: body, lobe and parametric fits fitted on the measurement
  std::string problem;  // empty for a meaningful fit; otherwise why it is not one
  std::vector<std::string> warnings;  // implausible values in the measurement or the fit (fit/plausibility.h)
  // With a source that holds back-scattering along azimuths (HalfDiffTable::source_backscatter); the rest of
  // the result is the isotropic fit of the table (for UTIA, the azimuthal mean).
  std::optional<AnisotropicFit> anisotropic;

  bool ok() const { return problem.empty(); }
  const TabulatedNdf& ndf() const { return lobe.ndf; }
  const FresnelCurve& fresnel() const { return lobe.fresnel; }
  const Rgb& body() const { return lobe.body; }
};

// f(k, k) per theta_h bin: the mean over phi_d of the theta_d = 0 bins (one configuration, stored 180
// times), as luminance. Bins with no valid measurement are left out.
Backscatter backscatter_of(const HalfDiffTable& table);

// Holds the quadrature of its resolution, so fitting many materials pays for it once. fit() is const
// and thread-safe.
class Fitter {
 public:
  explicit Fitter(const FitOptions& options);
  const FitOptions& options() const { return options_; }
  const Quadrature& quadrature() const { return quadrature_; }
  FitResult fit(const HalfDiffTable& table) const;

 private:
  // --refine full: the parametric fits and the body + tabulated lobe on the whole measurement.
  void refine_on_measurement(const HalfDiffTable& table, FitResult& result) const;
  // --refine none: the distances of the paper's representations from the measurement.
  void measure_paper_fits(const HalfDiffTable& table, FitResult& result) const;
  // Sources with azimuths (UTIA): the 2D extraction, its lobes and closures, into result.anisotropic.
  void fit_anisotropic(const HalfDiffTable& table, const FresnelCurve& paper_fresnel, FitResult& result) const;
  // The anisotropic GGX and Beckmann lobes of `a` (AnisotropicFit::ggx, beckmann) from its moment alphas.
  void fit_anisotropic_lobes(const HalfDiffTable& table, const FresnelCurve& paper_fresnel, const FitResult& result, AnisotropicFit& a) const;

  FitOptions options_;
  Quadrature quadrature_;
};

}  // namespace facetfit
