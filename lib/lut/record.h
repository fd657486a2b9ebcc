// The JSON record of one fit: `fit --json` prints it, `bake` writes it beside each LUT.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "fit/fit.h"

namespace facetfit {

// Keys: source, alpha_ggx, alpha_beckmann, f0, f82, iterations, residual, seconds. A meaningless fit
// has null parameters (JSON has no NaN).
nlohmann::json fit_record(const std::string& source, const FitResult& fit, double seconds);

}  // namespace facetfit
