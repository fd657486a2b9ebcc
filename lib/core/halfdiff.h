// Rusinkiewicz's half/difference angles, the coordinates of MERL tables.
//
// h = normalize(i + o); d is i expressed in the frame of h: rotate i by -phi_h about z, then by
// -theta_h about y. Swapping i and o maps phi_d to phi_d + pi, so a reciprocal BRDF has period pi in
// phi_d, which is why MERL stores phi_d in [0, pi) only.
#pragma once

#include <cmath>
#include <utility>

#include "core/frame.h"
#include "core/vec.h"

namespace facetfit {

struct HalfDiff {
  double theta_h = 0, phi_h = 0, theta_d = 0, phi_d = 0;
};

inline HalfDiff to_half_diff(const Vec3& o, const Vec3& i) {
  Vec3 h = i + o;
  const double len = glm::length(h);
  h = len > 1e-12 ? h / len : Vec3(0, 0, 1);
  HalfDiff hd;
  hd.theta_h = std::acos(clamp(h.z, -1.0, 1.0));
  hd.phi_h = std::atan2(h.y, h.x);
  // d = R_y(-theta_h) R_z(-phi_h) i, the rotations' cosines and sines read off h itself (no sincos: this
  // runs per evaluation of a MERL table).
  const double r = std::sqrt(h.x * h.x + h.y * h.y);
  const Vec3 t = (r > 0.0 ? TurnedFrame::of(h.x / r, h.y / r) : TurnedFrame()).to_frame(i);
  const double ct = clamp(h.z, -1.0, 1.0), st = r;
  const Vec3 d(ct * t.x - st * t.z, t.y, st * t.x + ct * t.z);
  hd.theta_d = std::acos(clamp(d.z, -1.0, 1.0));
  hd.phi_d = std::atan2(d.y, d.x);
  return hd;
}

// An angle's cosine and sine, for loops that meet each angle many times.
struct CosSin {
  double cos = 1.0, sin = 0.0;
  CosSin() = default;
  explicit CosSin(double angle) : cos(std::cos(angle)), sin(std::sin(angle)) {}
};

// The pair (o, i) at half/diff angles with phi_h = 0 (isotropic materials do not depend on phi_h):
// d = (sin theta_d cos phi_d, sin theta_d sin phi_d, cos theta_d), i = R_y(theta_h) d, o = i mirrored
// about h = (sin theta_h, 0, cos theta_h).
inline std::pair<Vec3, Vec3> from_half_diff(const CosSin& theta_h, const CosSin& theta_d, const CosSin& phi_d) {
  const Vec3 d(theta_d.sin * phi_d.cos, theta_d.sin * phi_d.sin, theta_d.cos);
  const double ct = theta_h.cos, st = theta_h.sin;
  const Vec3 i(ct * d.x + st * d.z, d.y, -st * d.x + ct * d.z);
  return {reflect_about(i, Vec3(st, 0.0, ct)), i};
}
inline std::pair<Vec3, Vec3> from_half_diff(double theta_h, double theta_d, double phi_d) {
  return from_half_diff(CosSin(theta_h), CosSin(theta_d), CosSin(phi_d));
}

}  // namespace facetfit
