#include "model/parametric.h"

#include <cmath>

#include "model/fresnel.h"

namespace facetfit {

std::optional<Rgb> ParametricBrdf::eval(const Vec3& o, const Vec3& i) const {
  if (i.z <= 0.0 || o.z <= 0.0) return Rgb(0.0);
  const Vec3 h = glm::normalize(i + o);
  const double cos_d = clamp(glm::dot(i, h), 0.0, 1.0);
  const Rgb fresnel = use_curve_ ? curve_.eval(std::acos(cos_d)) : fresnel_f82_tint(f0_, f82_, cos_d);
  return body_ * kInvPi + fresnel * (ndf_.D(h) * smith_g2(smith_, ndf_.lambda(i), ndf_.lambda(o)) / (4.0 * i.z * o.z)) +
         Rgb(coat_.eval(o, i));
}

}  // namespace facetfit
