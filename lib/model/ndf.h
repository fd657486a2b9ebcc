// Analytic microfacet distributions: GGX and Beckmann, anisotropic (alpha_x, alpha_y).
//
// D(h) is a density per steradian of microfacet normals normalized so that the projected area is
// one: integral of D(h) cos(theta_h) over the hemisphere = 1. The slope of normal h is
// (x~, y~) = (-h_x / h_z, -h_y / h_z) and slope_pdf(x~, y~) = D(h) cos^4(theta_h).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "core/vec.h"
#include "model/ggx_terms.h"

namespace facetfit {

enum class NdfType { ggx, beckmann };

const char* to_string(NdfType type);
std::optional<NdfType> parse_ndf_type(const std::string& name);

struct Ndf {
  NdfType type = NdfType::ggx;
  double alpha_x = 0.5;
  double alpha_y = 0.5;

  static Ndf isotropic(NdfType type, double alpha) { return {type, alpha, alpha}; }

  // Inline, with D and lambda: the renderer evaluates them several times per sample.
  double slope_pdf(double slope_x, double slope_y) const {
    const double r2 = (slope_x * slope_x) / (alpha_x * alpha_x) + (slope_y * slope_y) / (alpha_y * alpha_y);
    const double norm = 1.0 / (kPi * alpha_x * alpha_y);
    if (type == NdfType::ggx) return norm / ((1.0 + r2) * (1.0 + r2));
    return norm * std::exp(-r2);
  }
  // D(h) per steradian; zero for h below the horizon.
  double D(const Vec3& h) const {
    if (h.z <= 0.0) return 0.0;
    if (type == NdfType::ggx) {
      const double ax2 = alpha_x * alpha_x, ay2 = alpha_y * alpha_y;
      return ggx::D(ScalarOps{}, h.x, h.y, h.z, ax2, ay2, ax2 * alpha_x * ay2 * alpha_y / kPi);
    }
    const double c2 = h.z * h.z;
    return slope_pdf(-h.x / h.z, -h.y / h.z) / (c2 * c2);
  }
  // Smith's Lambda for direction w; sigma(w) = cos(theta_w) (1 + Lambda(w)) is the projected area.
  double lambda(const Vec3& w) const {
    if (w.z <= 0.0) return std::numeric_limits<double>::infinity();
    if (type == NdfType::ggx) return ggx::lambda(ScalarOps{}, w.x, w.y, w.z, alpha_x * alpha_x, alpha_y * alpha_y);
    return std::max(0.0, sigma(w) / w.z - 1.0);
  }
  double sigma(const Vec3& w) const;
  double g1(const Vec3& w) const { return w.z > 0.0 ? 1.0 / (1.0 + lambda(w)) : 0.0; }
};

}  // namespace facetfit
