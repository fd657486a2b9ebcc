// Vectors, colours and constants shared by every part of facetfit.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace facetfit {

using Vec3 = glm::dvec3;
using Rgb = glm::dvec3;  // linear RGB: Rec.709 primaries, or the working space a LUT or a render names (core/rgb_space.h)

constexpr double kPi = 3.14159265358979323846;
constexpr double kInvPi = 1.0 / kPi;

// Unit vector at polar angle theta from +z and azimuth phi from +x (local shading frame, z = normal).
inline Vec3 spherical_direction(double theta, double phi) {
  const double s = std::sin(theta);
  return {s * std::cos(phi), s * std::sin(phi), std::cos(theta)};
}

// o reflected about the unit normal h, 2 (o.h) h - o: a microfacet's light direction for the view o.
inline Vec3 reflect_about(const Vec3& o, const Vec3& h) { return 2.0 * glm::dot(o, h) * h - o; }

// Rec.709 / sRGB relative luminance.
inline double luminance(const Rgb& c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }

// Whether a microfacet lobe's f(o, i) can be formed: both directions above the horizon and, for its
// denominator 4 cos(theta_o) cos(theta_i), a product of the cosines that does not underflow to zero (both
// within ~1e-162 of the horizon, or one a denormal). Such a pair counts as on the horizon: f is 0 there,
// not 0 / 0. A direction with a NaN or infinite coordinate, or whose squared length overflows, is not
// above it (the tables a model indexes by angle would be indexed by NaN).
inline bool above_horizon(const Vec3& v) { return v.z > 0.0 && std::isfinite(glm::dot(v, v)); }
inline bool above_horizon(const Vec3& o, const Vec3& i) { return above_horizon(o) && above_horizon(i) && o.z * i.z > 0.0; }

inline double clamp(double x, double lo, double hi) { return x < lo ? lo : (x > hi ? hi : x); }

// The cube root, within 1e-15 relative of std::cbrt for normal numbers (tests/model/test_models.cpp) at 2.5x
// its speed: glibc's calls frexp and scalbn out of line. A first guess from the exponent's bits divided
// by three (within 6%), two Halley steps y (y^3 + 2x) / (2y^3 + x) (cubic: 1e-4, then 1e-12), one Newton
// step for the last digits. Zero, infinities and NaN come back as they are, negative x as -cbrt(-x).
inline double cube_root(double x) {
  if (x < 0.0) return -cube_root(-x);
  if (x == 0.0 || !std::isfinite(x)) return x;
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  bits = bits / 3 + 0x2A9F7893782DA1CEull;
  double y;
  std::memcpy(&y, &bits, sizeof y);
  for (int k = 0; k < 2; ++k) {
    const double y3 = y * y * y;
    y *= (y3 + 2.0 * x) / (2.0 * y3 + x);
  }
  return y - (y - x / (y * y)) * (1.0 / 3.0);
}

}  // namespace facetfit
