// Physical plausibility of a measurement and of its fit, reported rather than baked silently: a
// Fresnel factor above 1, a directional albedo above 1 (more light reflected than received), negative
// measurements (noise around zero: kept, but worth knowing).
#pragma once

#include <string>
#include <vector>

#include "core/brdf.h"
#include "io/merl.h"

namespace facetfit {

struct FitResult;

// Directional albedo rho(o) = integral of f(o, i) cos(theta_i) d(omega_i), per channel, by a stratified
// cosine-weighted grid of `n` x `n` directions. Missing values count as zero.
Rgb directional_albedo(const Brdf& brdf, const Vec3& o, int n = 16);

// One line per finding, each naming the quantity, its value and where: empty when all is plausible.
// `fit` may be the paper's alone (then its parametric fits are not checked: they are moment estimates).
std::vector<std::string> plausibility_warnings(const HalfDiffTable& table, const FitResult& fit);

}  // namespace facetfit
