// Smith masking-shadowing: the three ways facetfit couples masking G1 and shadowing into G2.
//
// All three are written through Smith's Lambda, with G1(k) = 1 / (1 + Lambda(k)) = cos(theta_k) / sigma(k).
// The formulas are in model/smith_terms-inl.h, which the renderer's SIMD lanes compile too.
#pragma once

#include <optional>
#include <string>

#include "model/scalar_ops.h"

namespace facetfit {

enum class Smith {
  // G2(o, i) = 1 / (1 + max(Lambda_o, Lambda_i)) = min(G1(o), G1(i)): fully direction-correlated.
  // It is the Smith form with G2(k, k) = G1(k), the back-scattering assumption of Dupuy et al. 2015.
  masking,
  // Height-correlated: G2 = 1 / (1 + Lambda_o + Lambda_i). pbrt-v4 and Cycles render with it.
  correlated,
  // Uncorrelated: G2 = G1(o) G1(i).
  separable,
};

namespace smith_formulas {
#include "model/smith_terms-inl.h"
}  // namespace smith_formulas

// G2 from the two Lambdas (smith_formulas::g2).
inline double smith_g2(Smith smith, double lambda_o, double lambda_i) { return smith_formulas::g2(ScalarOps{}, smith, lambda_o, lambda_i); }

// The same G2 from the two G1 values (G1 in [0, 1]; 0 at the horizon), without dividing by zero
// (smith_formulas::g2_from_g1).
inline double smith_g2_from_g1(Smith smith, double g1_o, double g1_i) { return smith_formulas::g2_from_g1(ScalarOps{}, smith, g1_o, g1_i); }

inline const char* to_string(Smith smith) {
  switch (smith) {
    case Smith::masking: return "masking";
    case Smith::correlated: return "correlated";
    case Smith::separable: return "separable";
  }
  return "?";
}

inline std::optional<Smith> parse_smith(const std::string& name) {
  if (name == "masking") return Smith::masking;
  if (name == "correlated") return Smith::correlated;
  if (name == "separable") return Smith::separable;
  return std::nullopt;
}

}  // namespace facetfit
