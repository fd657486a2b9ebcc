// A clear coat over a material: one GGX lobe with its own roughness and a grey Schlick Fresnel, height-
// correlated Smith masking. Layered materials (lacquered paint, vinyl films) show a sharp, uncoloured
// highlight above the broader, coloured reflection of what lies beneath; a single lobe cannot do both.
// The coat is added to the base (no energy exchange between the layers): the same plain sum the fits
// are made with.
#pragma once

#include <cmath>
#include <optional>

#include "core/vec.h"
#include "model/fresnel.h"
#include "model/ndf.h"
#include "model/smith.h"

namespace facetfit {

struct Coat {
  double alpha = 0.0;  // GGX roughness; 0: no coat
  double f0 = 0.0;     // normal-incidence reflectance (grey)

  bool present() const { return alpha > 0.0 && f0 > 0.0; }
  // f(o, i) of the coat alone, the same in R, G and B.
  double eval(const Vec3& o, const Vec3& i) const {
    if (!present() || i.z <= 0.0 || o.z <= 0.0) return 0.0;
    const Vec3 h = glm::normalize(i + o);
    const Ndf ndf = Ndf::isotropic(NdfType::ggx, alpha);
    const double f = fresnel_schlick(Rgb(f0), clamp(glm::dot(i, h), 0.0, 1.0)).r;
    return f * ndf.D(h) * smith_g2(Smith::correlated, ndf.lambda(i), ndf.lambda(o)) / (4.0 * i.z * o.z);
  }

  // A direction i for o from the GGX visible normals seen from o (Heitz 2018: the visible part of the
  // stretched hemisphere is a disk and a half-disk, sampled by warping one disk), reflected about h.
  std::optional<Vec3> sample_direction(const Vec3& o, double u1, double u2) const {
    if (!present() || o.z <= 0.0) return std::nullopt;
    const Vec3 v = glm::normalize(Vec3(alpha * o.x, alpha * o.y, o.z));  // to the unit-roughness frame
    const double len2 = v.x * v.x + v.y * v.y;
    const Vec3 t1 = len2 > 0.0 ? Vec3(-v.y, v.x, 0.0) / std::sqrt(len2) : Vec3(1.0, 0.0, 0.0);
    const Vec3 t2 = glm::cross(v, t1);
    const double r = std::sqrt(u1), phi = 2.0 * kPi * u2;
    const double p1 = r * std::cos(phi), s = 0.5 * (1.0 + v.z);
    const double p2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + s * r * std::sin(phi);
    const Vec3 n = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2)) * v;
    const Vec3 h = glm::normalize(Vec3(alpha * n.x, alpha * n.y, std::max(0.0, n.z)));
    const Vec3 i = 2.0 * glm::dot(o, h) * h - o;
    if (i.z <= 0.0) return std::nullopt;
    return i;
  }
  // Density of sample_direction() per steradian of i: G1(o) D(h) / (4 cos(theta_o)).
  double pdf(const Vec3& o, const Vec3& i) const {
    if (!present() || o.z <= 0.0 || i.z <= 0.0) return 0.0;
    const Vec3 h = glm::normalize(i + o);
    if (glm::dot(o, h) <= 0.0) return 0.0;
    const Ndf ndf = Ndf::isotropic(NdfType::ggx, alpha);
    return ndf.g1(o) * ndf.D(h) / (4.0 * o.z);
  }
};

}  // namespace facetfit
