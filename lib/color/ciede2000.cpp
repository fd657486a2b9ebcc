#include "color/ciede2000.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <system_error>

#include "core/error.h"
#include "core/vec.h"

namespace facetfit {

namespace {

constexpr double kDeg = 180.0 / kPi;
constexpr double kRad = kPi / 180.0;
constexpr double k25Pow7 = 6103515625.0;  // 25^7

// h' in degrees, in [0, 360); 0 where a' = b = 0, as the paper sets it.
double hue_degrees(double a_prime, double b) {
  if (a_prime == 0 && b == 0) return 0;
  const double h = std::atan2(b, a_prime) * kDeg;
  return h < 0 ? h + 360 : h;
}

// Whether |h1' - h2'| <= 180 degrees, the test on which both the hue difference and the mean hue branch
// (for C'1 C'2 != 0). Rounded degrees can put two hues that are exactly opposite, which the paper counts
// as <= 180 (as in its pairs 10 and 14: a'2 = -a'1, b2 = -b1), on either side of 180. Near 180 the answer
// comes instead from the cross product of (a'1, b1) and (a'2, b2), C'1 C'2 sin(h2' - h1'): exactly zero
// for exactly opposite vectors, and otherwise of the sign that tells on which side of 180 the real
// difference lies (sin(180 - e) > 0 > sin(180 + e)).
bool within_half_turn(double h1, double h2, double a1, double b1, double a2, double b2) {
  const double d = std::abs(h2 - h1);
  if (std::abs(d - 180) > 1e-6) return d <= 180;
  const double cross = a1 * b2 - b1 * a2;
  if (cross == 0) return true;
  return h2 > h1 ? cross > 0 : cross < 0;
}

}  // namespace

double ciede2000(const Lab& x, const Lab& y, double kL, double kC, double kH) {
  // a' stretches a* near the neutral axis, by G from the mean of the CIELAB chromas.
  const double c_ab = 0.5 * (std::hypot(x.a, x.b) + std::hypot(y.a, y.b));
  const double c_ab7 = std::pow(c_ab, 7);
  const double g = 0.5 * (1 - std::sqrt(c_ab7 / (c_ab7 + k25Pow7)));
  const double a1 = (1 + g) * x.a, a2 = (1 + g) * y.a;
  // hypot, not sqrt(a^2 + b^2): C' is zero exactly when a' = b = 0, so a zero chroma always has hue 0.
  const double c1 = std::hypot(a1, x.b), c2 = std::hypot(a2, y.b);
  const double h1 = hue_degrees(a1, x.b), h2 = hue_degrees(a2, y.b);

  // Hue difference and mean hue, with the paper's branches. "C'1 C'2 = 0" is tested factor by factor so
  // that an underflowing product of two tiny chromas does not count as zero.
  const bool achromatic = c1 == 0 || c2 == 0;
  double dh = 0, h_mean = h1 + h2;  // the paper's values where either chroma is zero
  if (!achromatic) {
    const bool within = within_half_turn(h1, h2, a1, x.b, a2, y.b);
    dh = h2 - h1;
    if (!within) dh += dh > 0 ? -360 : 360;
    if (within) h_mean = 0.5 * (h1 + h2);
    else h_mean = h1 + h2 < 360 ? 0.5 * (h1 + h2 + 360) : 0.5 * (h1 + h2 - 360);
  }
  const double dL = y.L - x.L;
  const double dC = c2 - c1;
  const double dH = 2 * std::sqrt(c1) * std::sqrt(c2) * std::sin(0.5 * dh * kRad);

  const double L_mean = 0.5 * (x.L + y.L);
  const double c_mean = 0.5 * (c1 + c2);
  const double t = 1 - 0.17 * std::cos((h_mean - 30) * kRad) + 0.24 * std::cos(2 * h_mean * kRad) +
                   0.32 * std::cos((3 * h_mean + 6) * kRad) - 0.20 * std::cos((4 * h_mean - 63) * kRad);
  const double u = (h_mean - 275) / 25;
  const double d_theta = 30 * std::exp(-u * u);  // degrees
  const double c_mean7 = std::pow(c_mean, 7);
  const double r_c = 2 * std::sqrt(c_mean7 / (c_mean7 + k25Pow7));
  const double l50 = (L_mean - 50) * (L_mean - 50);
  const double s_l = 1 + 0.015 * l50 / std::sqrt(20 + l50);
  const double s_c = 1 + 0.045 * c_mean;
  const double s_h = 1 + 0.015 * c_mean * t;
  const double r_t = -std::sin(2 * d_theta * kRad) * r_c;

  const double l = dL / (kL * s_l), c = dC / (kC * s_c), h = dH / (kH * s_h);
  // The sum is >= 0 in exact arithmetic (|R_T| < 2); max() guards sqrt against rounding at zero.
  return std::sqrt(std::max(0.0, l * l + c * c + h * h + r_t * c * h));
}

std::array<double, 6> parse_lab_pair(const std::string& line, const std::string& what) {
  std::array<double, 6> v{};
  std::size_t count = 0, i = 0;
  while (true) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    if (i == line.size()) break;
    std::size_t end = i;
    while (end < line.size() && line[end] != ' ' && line[end] != '\t') ++end;
    const std::string token = line.substr(i, end - i);
    if (count == 6) fail(what, "more than 6 numbers (expected L1 a1 b1 L2 a2 b2)");
    // from_chars: locale-independent, and it must consume the whole token.
    const char* first = token.data() + (token[0] == '+' ? 1 : 0);
    const char* last = token.data() + token.size();
    double x = 0;
    const auto [ptr, ec] = std::from_chars(first, last, x);
    if (ec != std::errc() || ptr != last || !std::isfinite(x)) fail(what, "'" + excerpt(token, 24) + "' is not a finite number");
    // Squares of larger values overflow inside the formula (1e308 gave a Delta E of 0).
    if (std::abs(x) > 1e6) fail(what, "'" + excerpt(token, 24) + "' is outside +-1e6: not a CIELAB coordinate");
    v[count++] = x;
    i = end;
  }
  if (count != 6) fail(what, std::to_string(count) + " numbers, expected 6 (L1 a1 b1 L2 a2 b2)");
  return v;
}

}  // namespace facetfit
