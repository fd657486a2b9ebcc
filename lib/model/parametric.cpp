#include "model/parametric.h"

#include <cmath>

#include "model/fresnel.h"

namespace facetfit {

std::optional<Rgb> ParametricBrdf::eval(const Vec3& o, const Vec3& i) const {
  if (!above_horizon(o, i)) return Rgb(0.0);
  const Vec3 h = glm::normalize(i + o);
  return eval_with(o, i, h, ndf_.D(h), ndf_.lambda(o));
}

Rgb ParametricBrdf::eval_with(const Vec3& o, const Vec3& i, const Vec3& h, double d, double lambda_o) const {
  const double cos_d = clamp(glm::dot(i, h), 0.0, 1.0);
  const Rgb fresnel = use_curve_ ? curve_.eval(std::acos(cos_d)) : f82_tint_.eval(cos_d);
  return body_ * kInvPi + fresnel * (d * smith_g2(smith_, lambda_o, ndf_.lambda(i)) / (4.0 * i.z * o.z)) + Rgb(coat_.eval(o, i));
}

}  // namespace facetfit
