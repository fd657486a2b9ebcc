#include "fit/fit.h"

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <tuple>
#include <utility>

#include "core/error.h"
#include "fit/plausibility.h"
#include "fit/roughness.h"
#include "model/fresnel.h"
#include "model/tabulated.h"
#include "model/parametric.h"
#include "model/proposal.h"
#include "model/visible_slopes.h"

namespace facetfit {

Backscatter backscatter_of(const HalfDiffTable& table) {
  Backscatter back;
  if (const BackscatterLattice& lattice = table.source_backscatter(); !lattice.empty()) {  // measured off the bins
    for (std::size_t p = 0; p < lattice.theta.size(); ++p) {
      back.theta.push_back(lattice.theta[p]);
      back.value.push_back(std::max(0.0, luminance(lattice.azimuthal_mean(int(p)))));  // below zero: noise on a zero measurement
    }
    return back;
  }
  for (int i = 0; i < HalfDiffTable::kThetaH; ++i) {
    Rgb mean(0.0);
    bool complete = true;
    for (int c = 0; c < 3 && complete; ++c) {
      const float* row = table.channel(c) + HalfDiffTable::index(i, 0, 0);
      double sum = 0.0;
      int n = 0;
      for (int k = 0; k < HalfDiffTable::kPhiD; ++k) {
        if (HalfDiffTable::missing(row[k])) continue;
        sum += row[k];
        ++n;
      }
      complete = n > 0;
      mean[c] = n > 0 ? sum / n : 0.0;
    }
    if (!complete) continue;
    back.theta.push_back(HalfDiffTable::theta_h(i));
    back.value.push_back(std::max(0.0, luminance(mean)));  // below zero: noise on a zero measurement
  }
  return back;
}

namespace {

// A Fresnel curve's reflectance at 0 and 82 degrees, clamped to [0, 1]: the parametric fits' start.
std::pair<Rgb, Rgb> f0_f82_of(const FresnelCurve& curve) {
  return {glm::clamp(curve.value[0], Rgb(0.0), Rgb(1.0)), glm::clamp(curve.eval(f82_theta()), Rgb(0.0), Rgb(1.0))};
}

// A source with two one-sided estimates (RGL) as a renderer shows it: f(o, i) read from the data of the
// view o, T(o, i) / cos theta_i (Mitsuba's `measured`); missing where o lies past the measured elevations.
class ViewSlices final : public Brdf {
 public:
  explicit ViewSlices(const OneSidedMeasurement& source) : source_(source) {}
  std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const override {
    if (o.z <= 0.0 || i.z <= 0.0) return Rgb(0.0);
    const std::optional<Rgb> t = source_.one_sided(o, i);
    if (!t) return std::nullopt;
    return *t / i.z;
  }

 private:
  const OneSidedMeasurement& source_;
};

// The distances a fit's representations are judged by (fit/measurement.h judged_distance): the bins' and the
// directional albedo's, each drawn by the representation's own proposal.
struct Judge {
  const MeasuredBins& bins;
  const AlbedoTarget& albedo;
  Smith smith;
  const ThetaGrid& grid;

  double of(const Brdf& model, const Proposal& proposal) const {
    return judged_distance(measurement_error(bins, model), albedo_distance(albedo, model, proposal));
  }
  double tabulated(const LobeFit& lobe) const {
    const MicrofacetTables tables = lobe.tables(smith);
    return of(TabulatedMicrofacet(tables, {}), VisibleSlopeProposal(tables));
  }
  double parametric(const ParametricFit& p) const {
    const ParametricBrdf model(Ndf::isotropic(p.type, p.alpha), smith, p.f0, p.f82, p.body, p.coat);
    if (p.type == NdfType::ggx) return of(model, GgxProposal(p.alpha, p.f0, p.body, p.coat));
    return of(model, VisibleSlopeProposal(tabulate_ndf(model.ndf(), grid), ProposalParts(p.f0, p.body, p.coat)));
  }
  double closures(const Closures& c) const { return of(ClosureBrdf(c), ClosureProposal(c)); }
};

// The measurement's directional albedo (of each view's own data where the source has them), drawn on a
// `grid` x `grid` per view by the extraction's proposal. None for a source measured at nodes of its own (a
// UTIA file, 15 degrees apart): its table interpolates between them, and the albedo of that interpolation says
// nothing of a lobe narrower than the nodes (GGX 0.005 written as UTIA: 8.3 at normal view, 149 at 76 degrees).
AlbedoTarget measured_albedo(const HalfDiffTable& table, const FitResult& paper, int grid) {
  if (table.source_samples()) return {};
  const VisibleSlopeProposal proposal(paper.lobe.tables(paper.smith));
  return table.source_one_sided() ? albedo_target(ViewSlices(*table.source_one_sided()), proposal, 10.0, grid)
                                  : albedo_target(table, proposal, 10.0, grid);
}

Quadrature checked_quadrature(const FitOptions& options) {
  if (options.resolution < kMinResolution || options.resolution > kMaxResolution)
    fail("resolution " + std::to_string(options.resolution),
         "must be between " + std::to_string(kMinResolution) + " and " + std::to_string(kMaxResolution));
  return Quadrature(options.resolution);
}

}  // namespace

Fitter::Fitter(const FitOptions& options) : options_(options), quadrature_(checked_quadrature(options)) {}

const char* to_string(FitOptions::Refine r) { return r == FitOptions::Refine::none ? "none" : "full"; }

std::optional<FitOptions::Refine> parse_refine(const std::string& name) {
  if (name == "none") return FitOptions::Refine::none;
  if (name == "full") return FitOptions::Refine::full;
  return std::nullopt;
}

const char* to_string(ClosureLobe::Fresnel f) { return f == ClosureLobe::Fresnel::schlick ? "schlick" : "f82"; }

std::optional<ClosureLobe::Fresnel> parse_closure_fresnel(const std::string& name) {
  if (name == "f82") return ClosureLobe::Fresnel::f82_tint;
  if (name == "schlick") return ClosureLobe::Fresnel::schlick;
  return std::nullopt;
}

void Fitter::refine_on_measurement(const HalfDiffTable& table, FitResult& result) const {
  const MeasuredBins fit_bins = solve_bins(table), parametric = parametric_bins(table), bins = error_bins(table);
  const Smith smith = options_.smith;
  // The albedo, drawn by the extraction's proposal: the tabulated lobe's refinements and the closures match it
  // beside the bins, and every representation is judged by both.
  const AlbedoTarget albedo = measured_albedo(table, result, 64);
  const Judge judge{bins, albedo, smith, quadrature_.grid()};
  result.error_extraction = judge.tabulated(result.lobe);

  // Parametric fits from the moment estimates (fit() set them), a grey body to start.
  const auto start = [](ParametricFit p) {
    p.body = Rgb(0.05);
    return p;
  };
  const auto fit = [&](const ParametricFit& p) { return fit_parametric(parametric, bins, smith, p); };
  // With a coat (a second, sharper GGX lobe) where it brings the fit 5% nearer.
  const auto fit_coated = [&](const ParametricFit& p) {
    const ParametricFit bare = fit(p);
    ParametricFit coated = bare;
    coated.coat = Coat{0.5 * std::min(bare.alpha, 0.3), 0.04};
    coated = fit(coated);
    return coated.error < 0.95 * bare.error ? coated : bare;
  };
  RefineOptions refine_options;
  refine_options.albedo = &albedo;
  LobeFit from_extraction;
  // Independent solves, run concurrently.
  tbb::parallel_invoke(
      [&] { result.ggx = fit_coated(start(result.ggx)), result.ggx.error = judge.parametric(result.ggx); },
      [&] { result.beckmann = fit_coated(start(result.beckmann)), result.beckmann.error = judge.parametric(result.beckmann); },
      [&] { result.lsq = fit(start(result.lsq)), result.lsq.error = judge.parametric(result.lsq); },
      [&] { from_extraction = refine_lobe(fit_bins, quadrature_, smith, result.lobe, refine_options); });

  // The tabulated lobe refined from a second start too: the nearer of the GGX and lsq fits, tabulated
  // (the tabulated model holds either exactly, so it can end no farther than they are).
  const ParametricFit& best = result.ggx.error <= result.lsq.error ? result.ggx : result.lsq;
  LobeFit tabulated;
  tabulated.ndf = tabulate_ndf(Ndf::isotropic(NdfType::ggx, best.alpha), quadrature_.grid());
  normalize_ndf(tabulated.ndf, quadrature_);
  for (int j = 0; j < FresnelCurve::kSize; ++j)  // F82-tint with f82 = Schlick(f0, 1/7) is Schlick
    tabulated.fresnel.value[std::size_t(j)] = fresnel_f82_tint(best.f0, best.f82, std::cos(FresnelCurve::theta_d(j)));
  tabulated.body = best.body;
  tabulated.coat = best.coat;
  const LobeFit from_best = refine_lobe(fit_bins, quadrature_, smith, tabulated, refine_options);

  // The nearest of the starts and the refinements by the bins' distance: a refinement that ends farther than
  // its start (a G2 update it could not follow, a bound) is not taken. (Between fits of one family the
  // albedo's distance is within the noise of its draws: on ground truth it took a GGX fit's F82-tint curve,
  // 0.007 off, over the exact refinement.)
  const auto bins_error = [&](const LobeFit& lobe) { return measurement_error(bins, TabulatedMicrofacet(lobe.tables(smith), {})); };
  const LobeFit* choice = &result.lobe;
  double nearest = bins_error(result.lobe);
  for (const LobeFit* candidate : std::array<const LobeFit*, 3>{&from_extraction, &tabulated, &from_best}) {
    const double error = bins_error(*candidate);
    if (error < nearest) nearest = error, choice = candidate;
  }
  // And by the judged distance never farther than the extraction it starts from.
  result.error = judge.tabulated(*choice);
  if (result.error > result.error_extraction) choice = &result.lobe, result.error = result.error_extraction;
  result.lobe = *choice;
  // The closures, from the GGX fit, matching the measurement's albedo too (fit/closure_fit.h), and never
  // farther than that fit, as one lobe, is: a solve that ends in a worse compromise gives the start.
  ClosureFitOptions closure_options;
  closure_options.fresnel = options_.closure_fresnel;
  closure_options.judge = [&](const Closures& c) { return judge.closures(c); };
  Closures ggx = closures_of(result.ggx);
  if (options_.closure_fresnel == ClosureLobe::Fresnel::schlick) ggx.lobes.front() = without_f82(ggx.lobes.front());
  result.closures = fit_closures(closure_bins(table), &albedo, bins, ggx, closure_options);
  result.closures.error = judge.closures(result.closures.closures);
  const double ggx_error = judge.closures(ggx);
  if (!(result.closures.error <= ggx_error)) result.closures = {ggx, ggx_error};
  result.alpha_ggx = alpha_ggx_from_moments(result.ndf(), quadrature_);
  result.alpha_beckmann = alpha_beckmann_from_moments(result.ndf(), quadrature_);
}

// The paper's method fits nothing more: its representations are only measured, so that the one
// recommended is chosen by distance from the measurement, as for a refined fit (fit/recommend.h), the albedo
// drawn as for a refined fit: on 32 x 32 points per view, an exact GGX moment fit was 0.0063 from its
// measurement, 0.0053 more than the tabulated lobe (the draws' noise), and not recommended.
void Fitter::measure_paper_fits(const HalfDiffTable& table, FitResult& result) const {
  const MeasuredBins bins = error_bins(table);
  if (bins.size() == 0) return;
  const AlbedoTarget albedo = measured_albedo(table, result, 64);
  const Judge judge{bins, albedo, options_.smith, quadrature_.grid()};
  // Four independent sums, each in its own order: concurrent, and the same to the bit at any thread count.
  const auto measure = [&](ParametricFit& p) { p.error = judge.parametric(p); };
  tbb::parallel_invoke([&] { result.error = judge.tabulated(result.lobe); }, [&] { measure(result.ggx); },
                       [&] { measure(result.beckmann); }, [&] { measure(result.lsq); });
  result.error_extraction = result.error;
}

void Fitter::fit_anisotropic_lobes(const HalfDiffTable& table, const FresnelCurve& paper_fresnel, const FitResult& result,
                                   AnisotropicFit& a) const {
  const auto moments = [&](NdfType type, const AnisotropicAlpha& alpha) {
    AnisotropicParametricFit p;
    p.type = type;
    p.alpha = alpha;
    std::tie(p.f0, p.f82) = f0_f82_of(paper_fresnel);
    return p;
  };
  a.ggx = moments(NdfType::ggx, a.alpha_ggx);
  a.beckmann = moments(NdfType::beckmann, a.alpha_beckmann);
  if (!result.refined) return;
  // Solved on every 24th of the lattice's nodes (5.7k; of a UTIA file's node pairs, 3.5k), measured on all
  // of them (138k; 83k).
  const MeasuredBins solve = anisotropic_bins(table, 24), all = anisotropic_bins(table, 1);
  if (solve.size() == 0 || all.size() == 0) return;
  const auto refined = [&](AnisotropicParametricFit start, const ParametricFit& isotropic) {
    start.body = isotropic.body;
    start.f0 = isotropic.f0;
    start.f82 = isotropic.f82;
    return fit_parametric_anisotropic(solve, all, options_.smith, start);
  };
  tbb::parallel_invoke([&] { a.ggx = refined(a.ggx, result.ggx); }, [&] { a.beckmann = refined(a.beckmann, result.beckmann); });
  a.refined = true;
}

namespace {

// The parametric representations of the paper's method: the moment alphas with the extraction's Fresnel at
// 0 and 82 degrees (Schlick's for lsq), no body; and the closures of the GGX one.
void moment_fits(FitResult& result) {
  const std::pair<Rgb, Rgb> reflectance = f0_f82_of(result.fresnel());
  const Rgb &f0 = reflectance.first, &f82 = reflectance.second;
  const auto moments = [&](NdfType type, double alpha, ParametricFit::FresnelForm form) {
    ParametricFit p;
    p.type = type;
    p.fresnel = form;
    p.alpha = alpha;
    p.f0 = f0;
    p.f82 = form == ParametricFit::FresnelForm::f82 ? f82 : fresnel_schlick(f0, 1.0 / 7.0);
    return p;
  };
  result.ggx = moments(NdfType::ggx, result.alpha_ggx, ParametricFit::FresnelForm::f82);
  result.beckmann = moments(NdfType::beckmann, result.alpha_beckmann, ParametricFit::FresnelForm::f82);
  result.lsq = moments(NdfType::ggx, result.alpha_ggx, ParametricFit::FresnelForm::schlick);
  result.closures.closures = closures_of(result.ggx);
}

// Why the moment alphas cannot be used, or empty. E|x| and E[x^2] of a distribution of slopes are positive;
// on a grid too coarse for a narrow lobe the quadrature's are not (the built-in aluminium's E|x| was negative
// with 5 or 6 intervals).
std::string moments_problem(const FitResult& result, int resolution) {
  if (result.alpha_ggx > 0.0 && result.alpha_beckmann > 0.0) return {};
  return "the extracted NDF's slope moments are not positive (alpha_ggx " + std::to_string(result.alpha_ggx) + ", alpha_beckmann " +
         std::to_string(result.alpha_beckmann) + ") at resolution " + std::to_string(resolution) + ": raise --resolution";
}

bool finite(const Rgb& c) { return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b); }

}  // namespace

FitResult Fitter::fit(const HalfDiffTable& table) const {
  // The paper's method: the NDF by power iteration on the back-scattering, then the Fresnel curve.
  FitResult result;
  result.smith = options_.smith;
  result.extraction = extract_ndf(backscatter_of(table), quadrature_, {options_.smith, options_.tolerance, options_.max_iterations});
  result.lobe.ndf = result.extraction.ndf;
  if (!result.extraction.problem.empty()) {
    result.problem = result.extraction.problem;
    return result;
  }
  const auto fresnel = fit_fresnel(table, result.ndf(), options_.smith);
  if (!fresnel) {
    result.problem = "no measurement where the microfacet model is nonzero (all missing?)";
    return result;
  }
  result.lobe.fresnel = *fresnel;

  // The parametric fits from the NDF's moments, then refined on the whole measurement (or measured as they are).
  result.refined = options_.refine == FitOptions::Refine::full;
  result.alpha_ggx = alpha_ggx_from_moments(result.ndf(), quadrature_);
  result.alpha_beckmann = alpha_beckmann_from_moments(result.ndf(), quadrature_);
  result.problem = moments_problem(result, options_.resolution);
  if (!result.ok()) return result;
  moment_fits(result);
  if (result.refined)
    refine_on_measurement(table, result);
  else
    measure_paper_fits(table, result);
  result.f0 = result.fresnel().value[0];
  result.f82 = result.fresnel().eval(f82_theta());

  if (!std::isfinite(result.alpha_ggx) || !std::isfinite(result.alpha_beckmann) || !finite(result.f0) || !finite(result.f82) ||
      !finite(result.body()))
    result.problem = "the fit produced non-finite parameters";
  if (result.ok()) result.warnings = plausibility_warnings(table, result);
  if (result.ok() && table.source_backscatter().azimuths > 1) fit_anisotropic(table, *fresnel, result);
  return result;
}

void Fitter::fit_anisotropic(const HalfDiffTable& table, const FresnelCurve& paper_fresnel, FitResult& result) const {
  // The same power iteration with the azimuth kept, on the source's own azimuths (6 ms at 90 x 48). Its
  // back-scattering has six polar angles: 90 intervals are plenty (the UTIA bar holds there), and a finer
  // isotropic --resolution would cost the 2D quadrature (J^2 M doubles) gigabytes. The lobe's Fresnel is the
  // paper's: the refinement is isotropic.
  const BackscatterLattice& lattice = table.source_backscatter();
  const Quadrature2D quadrature(std::min(options_.resolution, 90), lattice.azimuths);
  const Extraction2D e = extract_ndf_2d(backscatter_2d(lattice, quadrature), quadrature,
                                        {options_.smith, options_.tolerance, options_.max_iterations});
  if (!e.problem.empty()) {
    result.warnings.push_back("no anisotropic fit: " + e.problem);
    return;
  }
  AnisotropicFit a;
  a.alpha_ggx = alpha_ggx_2d(e.ndf, quadrature);
  a.alpha_beckmann = alpha_beckmann_2d(e.ndf, quadrature);
  a.iterations = e.iterations;
  a.residual = e.residual;
  a.tables = AnisotropicTables{quadrature.grid(), quadrature.phi_count(), e.ndf, e.sigma, options_.smith, paper_fresnel};
  fit_anisotropic_lobes(table, paper_fresnel, result, a);
  a.tables.axis = a.ggx.alpha.angle;
  result.closures = {closures_of(a.ggx), a.ggx.error};
  result.anisotropic = a;
  // Anisotropic beyond what the 15-degree grid resolves (a 10% ratio): say what an isotropic LUT loses.
  if (a.alpha_ggx.alpha_x > 1.1 * a.alpha_ggx.alpha_y) {
    char text[200];
    std::snprintf(text, sizeof text, "anisotropic (GGX %.3f x %.3f, x axis at %.0f degrees): the isotropic fits are of its azimuthal mean",
                  a.alpha_ggx.alpha_x, a.alpha_ggx.alpha_y, a.alpha_ggx.angle * 180.0 / kPi);
    result.warnings.push_back(text);
  }
}

}  // namespace facetfit
