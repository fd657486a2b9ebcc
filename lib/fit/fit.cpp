#include "fit/fit.h"

#include <cmath>

#include "core/error.h"
#include "fit/roughness.h"
#include "model/fresnel.h"
#include "model/tabulated.h"

namespace facetfit {

Backscatter backscatter_of(const MerlTable& table) {
  Backscatter back;
  for (int i = 0; i < MerlTable::kThetaH; ++i) {
    Rgb mean(0.0);
    bool complete = true;
    for (int c = 0; c < 3 && complete; ++c) {
      const float* row = table.channel(c) + MerlTable::index(i, 0, 0);
      double sum = 0.0;
      int n = 0;
      for (int k = 0; k < MerlTable::kPhiD; ++k) {
        if (row[k] < 0.0f) continue;
        sum += row[k];
        ++n;
      }
      complete = n > 0;
      mean[c] = n > 0 ? sum / n : 0.0;
    }
    if (!complete) continue;
    back.theta.push_back(MerlTable::theta_h(i));
    back.value.push_back(luminance(mean));
  }
  return back;
}

namespace {

Quadrature checked_quadrature(const FitOptions& options) {
  if (options.resolution < 4 || options.resolution > 4096)
    fail("--resolution " + std::to_string(options.resolution), "must be between 4 and 4096");
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

FitResult Fitter::fit(const MerlTable& table) const {
  FitResult result;
  result.smith = options_.smith;
  result.extraction = extract_ndf(backscatter_of(table), quadrature_,
                                  {options_.smith, options_.tolerance, options_.max_iterations});
  result.lobe.ndf = result.extraction.ndf;
  if (!result.extraction.problem.empty()) {
    result.problem = result.extraction.problem;
    return result;
  }
  result.lobe.fresnel = fit_fresnel(table, result.ndf(), options_.smith, &result.problem);
  if (!result.ok()) return result;

  const bool refine = options_.refine == FitOptions::Refine::full;
  result.refined = refine;
  // The paper's method alone measures nothing else: no bins, no errors (they stay 0).
  const MeasuredBins bins = refine ? measured_bins(table) : MeasuredBins{};
  const auto error_of = [&](const LobeFit& lobe) {
    return measurement_error(
        bins, TabulatedMicrofacet(MicrofacetTables{lobe.ndf, options_.smith, lobe.fresnel, lobe.body, lobe.coat}, {}));
  };
  if (refine) result.error_extraction = result.error = error_of(result.lobe);
  result.alpha_ggx = alpha_ggx_from_moments(result.ndf(), quadrature_);
  result.alpha_beckmann = alpha_beckmann_from_moments(result.ndf(), quadrature_);
  const Rgb f0 = result.fresnel().value[0], f82 = result.fresnel().eval(f82_theta());

  // Parametric fits, from the moments and the extraction's Fresnel, on a sparser set of bins (ten
  // parameters need far fewer than the tabulated lobe's hundreds).
  const auto start = [&](NdfType type, double alpha, ParametricFit::FresnelForm form) {
    ParametricFit p;
    p.type = type;
    p.fresnel = form;
    p.alpha = alpha;
    p.f0 = glm::clamp(f0, Rgb(0.0), Rgb(1.0));
    p.f82 = form == ParametricFit::FresnelForm::f82 ? glm::clamp(f82, Rgb(0.0), Rgb(1.0)) : fresnel_schlick(p.f0, 1.0 / 7.0);
    return p;
  };
  result.ggx = start(NdfType::ggx, result.alpha_ggx, ParametricFit::FresnelForm::f82);
  result.beckmann = start(NdfType::beckmann, result.alpha_beckmann, ParametricFit::FresnelForm::f82);
  result.lsq = start(NdfType::ggx, result.alpha_ggx, ParametricFit::FresnelForm::schlick);
  const MeasuredBins sparse = refine ? measured_bins(table, 3, 12) : MeasuredBins{};
  const auto fit_on = [&](const ParametricFit& p, int iterations) {
    ParametricFit f = fit_parametric(iterations > 0 ? sparse : bins, options_.smith, p, iterations);
    if (iterations > 0) f.error = fit_parametric(bins, options_.smith, f, 0).error;  // on the same bins as the rest
    return f;
  };
  if (refine) {
    result.ggx.body = result.beckmann.body = result.lsq.body = Rgb(0.05);
    result.ggx = fit_on(result.ggx, 50);
    result.beckmann = fit_on(result.beckmann, 50);
    result.lsq = fit_on(result.lsq, 50);
    // A coat: a second, sharper GGX lobe over each fit, kept where it brings the fit 5% nearer.
    for (ParametricFit* p : {&result.ggx, &result.beckmann}) {
      ParametricFit coated = *p;
      coated.coat = Coat{0.5 * std::min(p->alpha, 0.3), 0.04};
      coated = fit_on(coated, 50);
      if (coated.error < 0.95 * p->error) *p = coated;
    }
    // The tabulated lobe refined from the better start: the extraction, or the GGX fit tabulated.
    LobeFit from_ggx;
    from_ggx.ndf.grid = quadrature_.grid();
    const Ndf ggx = Ndf::isotropic(NdfType::ggx, result.ggx.alpha);
    for (int j = 0; j < quadrature_.size(); ++j) from_ggx.ndf.ndf.push_back(ggx.D(spherical_direction(quadrature_.grid().theta(j), 0.0)));
    normalize_ndf(from_ggx.ndf, quadrature_);
    for (int j = 0; j < FresnelCurve::kSize; ++j)
      from_ggx.fresnel.value[std::size_t(j)] = fresnel_f82_tint(result.ggx.f0, result.ggx.f82, std::cos(FresnelCurve::theta_d(j)));
    from_ggx.body = result.ggx.body;
    from_ggx.coat = result.ggx.coat;
    const LobeFit& base = result.ggx.error < result.error_extraction ? from_ggx : result.lobe;
    const double base_error = std::min(result.ggx.error, result.error_extraction);
    LobeFit refined = refine_lobe(bins, quadrature_, options_.smith, base, RefineOptions{});
    const double error = error_of(refined);
    // The refinement descends from its start; a pass that ends worse (a G2 update it could not follow,
    // the clamp to nonnegative values) is not taken.
    result.lobe = error <= base_error ? refined : base;
    result.error = std::min(error, base_error);
    result.alpha_ggx = alpha_ggx_from_moments(result.ndf(), quadrature_);
    result.alpha_beckmann = alpha_beckmann_from_moments(result.ndf(), quadrature_);
  }
  result.f0 = result.fresnel().value[0];
  result.f82 = result.fresnel().eval(f82_theta());

  const auto finite = [](const Rgb& c) { return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b); };
  if (!std::isfinite(result.alpha_ggx) || !std::isfinite(result.alpha_beckmann) || !finite(result.f0) ||
      !finite(result.f82) || !finite(result.body()))
    result.problem = "the fit produced non-finite parameters";
  return result;
}

}  // namespace facetfit
