#include "lut/record.h"

#include <fstream>

#include "fit/representations.h"

namespace facetfit {

nlohmann::json coat_json(const Coat& coat) {
  return coat.present() ? nlohmann::json{{"alpha", coat.alpha}, {"f0", coat.f0}} : nlohmann::json(nullptr);
}

nlohmann::json parametric_json(double alpha, const Rgb& body, const Rgb& f0, const Rgb& f82, const Coat& coat, double error) {
  const auto rgb = [](const Rgb& c) { return nlohmann::json{c.r, c.g, c.b}; };
  return {{"alpha", alpha}, {"body", rgb(body)}, {"f0", rgb(f0)}, {"f82", rgb(f82)}, {"coat", coat_json(coat)}, {"error", error}};
}

nlohmann::json principal_json(const AnisotropicAlpha& alpha) {
  return {{"alpha_x", alpha.alpha_x}, {"alpha_y", alpha.alpha_y}, {"angle_degrees", alpha.angle * 180.0 / kPi}};
}

nlohmann::json anisotropic_lobe_json(const AnisotropicParametricFit& lobe) {
  const auto rgb = [](const Rgb& c) { return nlohmann::json{c.r, c.g, c.b}; };
  nlohmann::json l = principal_json(lobe.alpha);
  l["body"] = rgb(lobe.body), l["f0"] = rgb(lobe.f0), l["f82"] = rgb(lobe.f82), l["error"] = lobe.error;
  return l;
}

nlohmann::json closures_json(const Closures& closures, double error) {
  const auto rgb = [](const Rgb& c) { return nlohmann::json{c.r, c.g, c.b}; };
  nlohmann::json lobes = nlohmann::json::array();
  for (const ClosureLobe& l : closures.lobes) {
    nlohmann::json lobe = {{"family", to_string(l.type)}, {"alpha_x", l.alpha_x}, {"alpha_y", l.alpha_y},
                           {"angle_degrees", l.angle * 180.0 / kPi}, {"view_exponent", l.view_exponent}, {"weight", l.weight},
                           {"f0", rgb(l.f0)}};
    if (l.fresnel == ClosureLobe::Fresnel::f82_tint)
      lobe["fresnel"] = "f82_tint", lobe["f82"] = rgb(l.f82);
    else
      lobe["fresnel"] = "schlick", lobe["f90"] = rgb(l.f90), lobe["exponent"] = l.exponent;
    lobes.push_back(lobe);
  }
  return {{"body", rgb(closures.body)}, {"lobes", lobes}, {"coat", coat_json(closures.coat)}, {"error", error}};
}

nlohmann::json recommended_json(const RepresentationParameters& p, double tolerance) {
  nlohmann::json j = parametric_json(p.alpha.value_or(0.0), p.body, p.f0, p.f82, p.coat, p.error);
  if (!p.alpha) j["alpha"] = nullptr;
  j["representation"] = to_string(p.representation);
  j["tolerance"] = tolerance;
  return j;
}

std::string json_text(const nlohmann::json& j, int indent) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

nlohmann::json read_json_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) return nullptr;
  nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  return j.is_discarded() ? nlohmann::json(nullptr) : j;
}

nlohmann::json fit_record(const std::string& source, const FitResult& fit, double seconds, double tolerance) {
  const auto rgb = [](const Rgb& c) { return nlohmann::json{c.r, c.g, c.b}; };
  nlohmann::json j;
  j["source"] = source;
  if (fit.ok()) {
    j["recommended"] = recommended_json(parameters_of(fit, recommend(fit, tolerance)), tolerance);
    j["alpha_ggx"] = fit.alpha_ggx;
    j["alpha_beckmann"] = fit.alpha_beckmann;
    j["f0"] = rgb(fit.f0);
    j["f82"] = rgb(fit.f82);
    j["refine"] = fit.refined ? "full" : "none";
    j["body"] = rgb(fit.body());
    j["body_exponent"] = fit.lobe.body_exponent;
    j["coat"] = coat_json(fit.lobe.coat);
    j["error"] = fit.error;
    j["error_extraction"] = fit.error_extraction;
    for (const RepresentationRow& r : kRepresentations)  // ggx, beckmann, lsq (fit/representations.h)
      if (r.parametric) {
        const ParametricFit& p = fit.*r.parametric;
        j[r.name] = parametric_json(p.alpha, p.body, p.f0, p.f82, p.coat, p.error);
      }
    j["closures"] = closures_json(fit.closures.closures, fit.closures.error);
    j["warnings"] = fit.warnings;
    j["anisotropic"] = nullptr;
    if (const auto& a = fit.anisotropic)
      j["anisotropic"] = {{"alpha_ggx", principal_json(a->alpha_ggx)}, {"alpha_beckmann", principal_json(a->alpha_beckmann)},
                          {"ggx", anisotropic_lobe_json(a->ggx)}, {"beckmann", anisotropic_lobe_json(a->beckmann)},
                          {"refine", a->refined ? "full" : "none"}, {"iterations", a->iterations}, {"residual", a->residual}};
  } else {
    for (const char* k : {"recommended", "alpha_ggx", "alpha_beckmann", "f0", "f82"}) j[k] = nullptr;
  }
  j["iterations"] = fit.extraction.iterations;
  j["residual"] = fit.extraction.residual;
  j["seconds"] = seconds;
  return j;
}

}  // namespace facetfit
