// What the formulas written once over a number type F (model/*_terms-inl.h, model/ggx_visible-inl.h) need
// of F = double beyond its operators: division, the square root, constants, min and max, and choices by
// sign. The renderer's SIMD lanes give the same for Highway's vectors (LaneOps, render/lanes-inl.h).
#pragma once

#include <algorithm>
#include <cmath>

namespace facetfit {

struct ScalarOps {
  static double divide(double a, double b) { return a / b; }
  static double reciprocal(double x) { return 1.0 / x; }
  static double sqrt(double x) { return std::sqrt(x); }
  static double inverse_sqrt(double x) { return 1.0 / std::sqrt(x); }
  static double constant(double c) { return c; }
  static double negate(double x) { return -x; }
  static double min(double a, double b) { return std::min(a, b); }
  static double max(double a, double b) { return std::max(a, b); }
  // v where x > 0, else 0.
  static double where_positive(double x, double v) { return x > 0.0 ? v : 0.0; }
  // a / sqrt(b) (the lanes multiply by an inverse square root).
  static double divide_by_sqrt(double a, double b) { return a / std::sqrt(b); }
  // a where x > 0, else b.
  static double select_positive(double x, double a, double b) { return x > 0.0 ? a : b; }
  // x where x > 0, else `otherwise`: a divisor that stays harmless in the lanes that discard the quotient.
  static double positive_or(double x, double otherwise) { return x > 0.0 ? x : otherwise; }
};

}  // namespace facetfit
