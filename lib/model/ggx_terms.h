// GGX's D and Smith's Lambda, written once over a number type F (model/ggx_terms-inl.h): double for the
// library (model/ndf.h) and Highway's vectors in the renderer's SIMD lanes (render/lanes-inl.h), as
// Mitsuba writes a BSDF once over its Float. `Ops` gives what F's operators do not: division, the square
// root, constants and a choice by sign (ScalarOps below; LaneOps in render/lanes-inl.h).
#pragma once

#include <cmath>

namespace facetfit::ggx {

#include "model/ggx_terms-inl.h"

struct ScalarOps {
  static double divide(double a, double b) { return a / b; }
  static double sqrt(double x) { return std::sqrt(x); }
  static double constant(double c) { return c; }
  static double where_positive(double x, double v) { return x > 0.0 ? v : 0.0; }
};

}  // namespace facetfit::ggx
