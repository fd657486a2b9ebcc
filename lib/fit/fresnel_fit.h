// The RGB Fresnel curve: at each theta_d, the mean ratio of the measurement to the ideal-mirror
// microfacet model (the extracted D and G with F = 1).
#pragma once

#include <array>
#include <optional>
#include <cstdint>
#include <string>
#include <vector>

#include "model/fresnel_curve.h"
#include "model/tabulated_ndf.h"
#include "io/merl.h"
#include "model/smith.h"

namespace facetfit {

// One pass over every valid bin of the table. Each theta_d entry is the mean of the ratios
// measurement / model weighted by the model: sum(measurement) / sum(model). The unweighted mean is
// dominated by the bins where the F = 1 model is nearly zero, i.e. by noise and by what is not
// microfacet reflection. nullopt when no bin holds a usable measurement in some channel (a fit
// without meaning, not an error: Fitter::fit reports it in FitResult::problem).
std::optional<FresnelCurve> fit_fresnel(const HalfDiffTable& table, const TabulatedNdf& ndf, Smith smith);

}  // namespace facetfit
