// Sampling GGX's visible normals (Heitz 2018, "Sampling the GGX Distribution of Visible Normals"): seen
// from o, the visible part of the stretched unit hemisphere projects to a disk and a half-disk, sampled by
// warping one disk; the normal is stretched back and o reflected about it. Density per steradian of the
// reflected direction i: G1(o) D(h) / (4 cos(theta_o)). Used by the coat and by the proposal of every
// GGX material (model/proposal.h).
#pragma once

#include <cmath>
#include <optional>

#include "core/vec.h"
#include "model/ndf.h"
#include "model/scalar_ops.h"

namespace facetfit {

namespace ggx {
#include "model/ggx_visible-inl.h"
}  // namespace ggx

// The reflected direction of a visible normal of GGX (alpha_x, alpha_y along the frame's axes) seen from o,
// from the point (r cos phi, r sin phi) of the unit disk that ggx_visible_direction's two numbers map to
// (r = sqrt(u1), phi = 2 pi u2), for callers that draw on a fixed grid and keep the cosines.
inline std::optional<Vec3> ggx_visible_direction_of_disk(const Vec3& o, double alpha_x, double alpha_y, double r, double cos_phi,
                                                         double sin_phi) {
  if (o.z <= 0.0) return std::nullopt;
  Vec3 h;
  ggx::visible_normal(ScalarOps{}, o.x, o.y, o.z, alpha_x, alpha_y, r, cos_phi, sin_phi, h.x, h.y, h.z);
  const Vec3 i = reflect_about(o, h);
  if (i.z <= 0.0) return std::nullopt;
  return i;
}

inline std::optional<Vec3> ggx_visible_direction_of_disk(const Vec3& o, double alpha, double r, double cos_phi, double sin_phi) {
  return ggx_visible_direction_of_disk(o, alpha, alpha, r, cos_phi, sin_phi);
}

inline std::optional<Vec3> ggx_visible_direction(const Vec3& o, double alpha, double u1, double u2) {
  const double phi = 2.0 * kPi * u2;
  return ggx_visible_direction_of_disk(o, alpha, std::sqrt(u1), std::cos(phi), std::sin(phi));
}

// The density from its parts, for callers that have them: D(h) and G1(o) for h = normalize(i + o), o and i
// above the horizon.
inline double ggx_visible_pdf_of(const Vec3& o, const Vec3& h, double d, double g1_o) {
  return glm::dot(o, h) > 0.0 ? g1_o * d / (4.0 * o.z) : 0.0;
}

inline double ggx_visible_pdf(const Vec3& o, const Vec3& i, double alpha) {
  if (o.z <= 0.0 || i.z <= 0.0) return 0.0;
  const Vec3 h = glm::normalize(i + o);
  const Ndf ndf = Ndf::isotropic(NdfType::ggx, alpha);
  return ggx_visible_pdf_of(o, h, ndf.D(h), ndf.g1(o));
}

// The same of GGX `ndf` (alpha_x, alpha_y along the frame's axes; o and i in that frame).
inline std::optional<Vec3> ggx_visible_direction(const Vec3& o, const Ndf& ndf, double u1, double u2) {
  const double phi = 2.0 * kPi * u2;
  return ggx_visible_direction_of_disk(o, ndf.alpha_x, ndf.alpha_y, std::sqrt(u1), std::cos(phi), std::sin(phi));
}
inline double ggx_visible_pdf(const Vec3& o, const Vec3& i, const Ndf& ndf) {
  if (o.z <= 0.0 || i.z <= 0.0) return 0.0;
  const Vec3 h = glm::normalize(i + o);
  return ggx_visible_pdf_of(o, h, ndf.D(h), ndf.g1(o));
}

}  // namespace facetfit
