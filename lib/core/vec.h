// Vectors, colours and constants shared by every part of facetfit.
#pragma once

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace facetfit {

using Vec3 = glm::dvec3;
using Rgb = glm::dvec3;  // linear RGB, Rec.709 primaries

constexpr double kPi = 3.14159265358979323846;
constexpr double kInvPi = 1.0 / kPi;

// Unit vector at polar angle theta from +z and azimuth phi from +x (local shading frame, z = normal).
inline Vec3 spherical_direction(double theta, double phi) {
  const double s = std::sin(theta);
  return {s * std::cos(phi), s * std::sin(phi), std::cos(theta)};
}

// Rec.709 / sRGB relative luminance.
inline double luminance(const Rgb& c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }

inline double clamp(double x, double lo, double hi) { return x < lo ? lo : (x > hi ? hi : x); }

}  // namespace facetfit
