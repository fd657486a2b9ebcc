#include "lut/record.h"

namespace facetfit {

nlohmann::json fit_record(const std::string& source, const FitResult& fit, double seconds) {
  const auto rgb = [](const Rgb& c) { return nlohmann::json{c.r, c.g, c.b}; };
  nlohmann::json j;
  j["source"] = source;
  if (fit.ok()) {
    j["alpha_ggx"] = fit.alpha_ggx;
    j["alpha_beckmann"] = fit.alpha_beckmann;
    j["f0"] = rgb(fit.f0);
    j["f82"] = rgb(fit.f82);
  } else {
    for (const char* k : {"alpha_ggx", "alpha_beckmann", "f0", "f82"}) j[k] = nullptr;
  }
  j["iterations"] = fit.extraction.iterations;
  j["residual"] = fit.extraction.residual;
  j["seconds"] = seconds;
  return j;
}

}  // namespace facetfit
