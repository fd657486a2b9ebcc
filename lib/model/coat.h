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
#include "model/ggx_visible.h"
#include "model/ndf.h"
#include "model/smith.h"

namespace facetfit {

struct Coat {
  double alpha = 0.0;  // GGX roughness; 0: no coat
  double f0 = 0.0;     // normal-incidence reflectance (grey)

  bool present() const { return alpha > 0.0 && f0 > 0.0; }
  // f(o, i) of the coat alone, the same in R, G and B.
  double eval(const Vec3& o, const Vec3& i) const {
    if (!present() || !above_horizon(o, i)) return 0.0;
    const Vec3 h = glm::normalize(i + o);
    const Ndf ndf = Ndf::isotropic(NdfType::ggx, alpha);
    const double f = fresnel_schlick(Rgb(f0), clamp(glm::dot(i, h), 0.0, 1.0)).r;
    return f * ndf.D(h) * smith_g2(Smith::correlated, ndf.lambda(o), ndf.lambda(i)) / (4.0 * i.z * o.z);
  }

  // A direction i for o from the coat's visible normals (model/ggx_visible.h), and its density.
  std::optional<Vec3> sample_direction(const Vec3& o, double u1, double u2) const {
    return present() ? ggx_visible_direction(o, alpha, u1, u2) : std::nullopt;
  }
  double pdf(const Vec3& o, const Vec3& i) const { return present() ? ggx_visible_pdf(o, i, alpha) : 0.0; }
};

}  // namespace facetfit
