#include "model/analytic.h"

#include "model/body.h"

namespace facetfit {

std::optional<Rgb> MicrofacetBrdf::eval(const Vec3& o, const Vec3& i) const {
  if (!above_horizon(o, i)) return Rgb(0.0);
  const Vec3 h = glm::normalize(i + o);
  const double g2 = smith_g2(smith_, ndf_.lambda(o), ndf_.lambda(i));
  const double scalar = ndf_.D(h) * g2 / (4.0 * i.z * o.z);
  return fresnel_.eval(glm::dot(i, h)) * scalar;
}

std::optional<Rgb> LambertBrdf::eval(const Vec3& o, const Vec3& i) const {
  if (i.z <= 0.0 || o.z <= 0.0) return Rgb(0.0);
  return albedo_ * (kInvPi * minnaert_factor(exponent_, o.z, i.z));
}

std::optional<Rgb> SumBrdf::eval(const Vec3& o, const Vec3& i) const {
  Rgb sum(0.0);
  for (const auto& lobe : lobes_) {
    const auto f = lobe->eval(o, i);
    if (!f) return std::nullopt;
    sum += *f;
  }
  return sum;
}

}  // namespace facetfit
