#include "model/visible_azimuth.h"

#include <algorithm>
#include <cmath>

#include "core/vec.h"

namespace facetfit {

namespace {

struct AzimuthRange {
  double phi_max, total;  // the CDF's end and its value there
};

// total is half of positive_phi_integral(a, b) (core/quadrature_rules.h), written here to share phi_max's
// arc cosine, with sin(phi_max) = sqrt(1 - (b / a)^2) where a > b (no sine of the arc cosine), as the
// lanes compute it (render/tabulated_batch.cpp, sample_phi).
AzimuthRange azimuth_range(double a, double b) {
  if (a <= b) return {kPi, b * kPi};
  const double ratio = -b / a, phi_max = std::acos(ratio);
  return {phi_max, a * std::sqrt(std::max(0.0, 1.0 - ratio * ratio)) + b * phi_max};
}

}  // namespace

AzimuthGuess::AzimuthGuess() {
  for (int i = 0; i <= kSize; ++i) {
    const double a = double(i) / kSize, b = 1.0 - a;
    const AzimuthRange range = azimuth_range(a, b);
    // The ends exactly: at u = 1 with a > b the CDF is flat to rounding over ~1e-8 radians below phi_max.
    values_[std::size_t(i * kStride + kSize)] = 1.0;
    for (int j = 1; j < kSize; ++j) {
      // Bisection to the last bit: slow and sure, once.
      const double target = double(j) / kSize * range.total;
      double lo = 0.0, hi = range.phi_max;
      for (int it = 0; it < 64; ++it) {
        const double mid = 0.5 * (lo + hi);
        (a * std::sin(mid) + b * mid > target ? hi : lo) = mid;
      }
      values_[std::size_t(i * kStride + j)] = 0.5 * (lo + hi) / range.phi_max;
    }
  }
}

const AzimuthGuess& AzimuthGuess::table() {
  static const AzimuthGuess guess;
  return guess;
}

double AzimuthGuess::operator()(double a, double b, double u, double phi_max) const {
  const double x = clamp(a / (a + b), 0.0, 1.0) * kSize, y = clamp(u, 0.0, 1.0) * kSize;
  const int i = std::min(int(x), kSize - 1), j = std::min(int(y), kSize - 1);
  const double t = x - i, w = y - j;
  const double* row = values_.data() + std::size_t(i * kStride + j);
  const double near = row[0] + w * (row[1] - row[0]), far = row[kStride] + w * (row[kStride + 1] - row[kStride]);
  return (near + t * (far - near)) * phi_max;
}

std::pair<double, double> sample_visible_azimuth(double a, double b, double u) {
  const double sign = u < 0.5 ? -1.0 : 1.0;
  u = u < 0.5 ? 2.0 * u : 2.0 * u - 1.0;
  const AzimuthRange range = azimuth_range(a, b);
  if (!(range.total > 0.0)) return {std::cos(u * kPi), sign * std::sin(u * kPi)};
  const double target = u * range.total;
  // Newton on the monotone CDF, kept inside the bracket. Near phi_max the density vanishes and the last
  // digits of f are rounding noise: a tighter stop there costs ~7 more iterations.
  double lo = 0.0, hi = range.phi_max, phi = AzimuthGuess::table()(a, b, u, range.phi_max), s = 0.0, c = 1.0;
  for (int it = 0; it < 40; ++it) {
    s = std::sin(phi), c = std::cos(phi);  // one sincos
    const double f = a * s + b * phi - target;
    if (f > 0.0) hi = phi; else lo = phi;
    const double df = a * c + b;
    double next = df > 0.0 ? phi - f / df : 0.5 * (lo + hi);
    if (!(next >= lo && next <= hi)) next = 0.5 * (lo + hi);  // a guess on the root stays
    const double step = next - phi;
    if (std::abs(step) < 1e-7) {  // radians: below what a float ray direction resolves
      // The rotation by the last step to first order (its square, < 1e-14, is below double rounding).
      return {c - s * step, sign * (s + c * step)};
    }
    phi = next;
  }
  return {std::cos(phi), sign * std::sin(phi)};
}

}  // namespace facetfit
