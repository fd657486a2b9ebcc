// Analytic microfacet distributions: GGX and Beckmann, anisotropic (alpha_x, alpha_y).
//
// D(h) is a density per steradian of microfacet normals normalized so that the projected area is
// one: integral of D(h) cos(theta_h) over the hemisphere = 1. The slope of normal h is
// (x~, y~) = (-h_x / h_z, -h_y / h_z) and slope_pdf(x~, y~) = D(h) cos^4(theta_h).
#pragma once

#include <optional>
#include <string>

#include "core/vec.h"

namespace facetfit {

enum class NdfType { ggx, beckmann };

const char* to_string(NdfType type);
std::optional<NdfType> parse_ndf_type(const std::string& name);

struct Ndf {
  NdfType type = NdfType::ggx;
  double alpha_x = 0.5;
  double alpha_y = 0.5;

  static Ndf isotropic(NdfType type, double alpha) { return {type, alpha, alpha}; }

  double slope_pdf(double slope_x, double slope_y) const;
  // D(h) per steradian; zero for h below the horizon.
  double D(const Vec3& h) const;
  // Smith's Lambda for direction w; sigma(w) = cos(theta_w) (1 + Lambda(w)) is the projected area.
  double lambda(const Vec3& w) const;
  double sigma(const Vec3& w) const;
  double g1(const Vec3& w) const { return w.z > 0.0 ? 1.0 / (1.0 + lambda(w)) : 0.0; }
};

}  // namespace facetfit
