// The JSON record of one fit: `fit --json` prints it, `bake` writes it beside each LUT.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "fit/fit.h"
#include "fit/recommend.h"

namespace facetfit {

// The record's layout: part of the bake cache's key, so that a cache written before a change of keys (2: the
// `anisotropic` key; 3: anisotropic inputs bake LUT version 3; 4: the anisotropic record and LUT carry the anisotropic GGX fit with its body; 5: `body_exponent`; 6: `closures`;
// 7: `recommended`) is baked again rather than served with the old outputs. Bump with every such change.
constexpr int kRecordVersion = 7;

// The JSON text of `j` (indented when indent >= 0). Strings that are not UTF-8 (a file name's bytes)
// are written with U+FFFD in place of the bad bytes rather than failing the whole write.
std::string json_text(const nlohmann::json& j, int indent = -1);

// The JSON a file holds (a sidecar, index.json, report.json); null when it is absent or not JSON, which
// the callers all treat as "nothing there yet".
nlohmann::json read_json_file(const std::string& path);

// Keys: source, recommended (recommended_json, under `tolerance`), alpha_ggx and alpha_beckmann (the
// paper's moment estimates of the tabulated NDF, not a fit), f0, f82 (of the tabulated representation), refine, body,
// coat, error, error_extraction, ggx / beckmann / lsq (parametric_json), closures (closures_json), warnings, anisotropic (null, or
// for a UTIA source {ggx, beckmann: {alpha_x, alpha_y, angle_degrees}, iterations, residual}), iterations,
// residual, seconds. A meaningless fit has null parameters (JSON has no NaN).
nlohmann::json fit_record(const std::string& source, const FitResult& fit, double seconds, double tolerance = kDefaultTolerance);

// A coat as {alpha, f0}, null when absent; a parametric fit as {alpha, body, f0, f82, coat, error}; the
// closures (model/closures.h) as {body, lobes: [{family, alpha_x, alpha_y, angle_degrees, weight, fresnel
// ("f82_tint" with f0, f82, or "schlick" with f0, f90, exponent)}], coat, error}.
nlohmann::json coat_json(const Coat& coat);
nlohmann::json parametric_json(double alpha, const Rgb& body, const Rgb& f0, const Rgb& f82, const Coat& coat, double error);
nlohmann::json closures_json(const Closures& closures, double error);
// Principal alphas as {alpha_x, alpha_y, angle_degrees}; an anisotropic lobe with its body as those and
// {body, f0, f82, error}.
nlohmann::json principal_json(const AnisotropicAlpha& alpha);
nlohmann::json anisotropic_lobe_json(const AnisotropicParametricFit& lobe);
// The recommended representation and its own parameters (fit/recommend.h): {representation, tolerance,
// alpha (null for the tabulated one), body, f0, f82, coat, error}.
nlohmann::json recommended_json(const RepresentationParameters& p, double tolerance);

}  // namespace facetfit
