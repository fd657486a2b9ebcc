#include "model/ndf.h"

#include <cmath>
#include <algorithm>
#include <limits>

namespace facetfit {

const char* to_string(NdfType type) { return type == NdfType::ggx ? "ggx" : "beckmann"; }

std::optional<NdfType> parse_ndf_type(const std::string& name) {
  if (name == "ggx") return NdfType::ggx;
  if (name == "beckmann") return NdfType::beckmann;
  return std::nullopt;
}

double Ndf::sigma(const Vec3& w) const {
  // Closed forms of sigma(w) = integral of max(0, w.h) D(h) dw_h, valid for any w (also at and below
  // the horizon, where cos(theta)(1 + Lambda) would be 0 * inf). Both satisfy sigma(w) - sigma(-w) = w.z.
  const double c = w.z;
  const double sin2 = w.x * w.x + w.y * w.y;
  if (sin2 <= 0.0) return c > 0.0 ? c : 0.0;
  const double alpha = std::sqrt((w.x * w.x * alpha_x * alpha_x + w.y * w.y * alpha_y * alpha_y) / sin2);
  const double s = std::sqrt(sin2);
  if (type == NdfType::ggx) return 0.5 * (c + std::sqrt(c * c + alpha * alpha * sin2));
  // Beckmann, with a = cot(theta) / alpha.
  const double a = c / (alpha * s);
  return 0.5 * c * (1.0 + std::erf(a)) + alpha * s * std::exp(-a * a) / (2.0 * std::sqrt(kPi));
}

}  // namespace facetfit
