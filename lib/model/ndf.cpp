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

double Ndf::slope_pdf(double slope_x, double slope_y) const {
  const double r2 = (slope_x * slope_x) / (alpha_x * alpha_x) + (slope_y * slope_y) / (alpha_y * alpha_y);
  const double norm = 1.0 / (kPi * alpha_x * alpha_y);
  if (type == NdfType::ggx) return norm / ((1.0 + r2) * (1.0 + r2));
  return norm * std::exp(-r2);
}

double Ndf::D(const Vec3& h) const {
  if (h.z <= 0.0) return 0.0;
  const double c2 = h.z * h.z;
  return slope_pdf(-h.x / h.z, -h.y / h.z) / (c2 * c2);
}

double Ndf::lambda(const Vec3& w) const {
  if (w.z <= 0.0) return std::numeric_limits<double>::infinity();
  return std::max(0.0, sigma(w) / w.z - 1.0);
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
