#include "fit/plausibility.h"

#include <cmath>
#include <cstdio>
#include <optional>

#include "fit/fit.h"
#include "fit/representations.h"
#include "model/parametric.h"
#include "model/proposal.h"
#include "model/tabulated.h"

namespace facetfit {

namespace {

std::string format(const char* fmt, double a, double b = 0.0, double c = 0.0) {
  char buf[200];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

// The largest channel value of `v` above `limit`: (channel, value), or channel -1.
std::pair<int, double> above(const Rgb& v, double limit) {
  int c = -1;
  double worst = limit;
  for (int k = 0; k < 3; ++k)
    if (v[k] > worst) worst = v[k], c = k;
  return {c, worst};
}

}  // namespace

Rgb directional_albedo(const Brdf& brdf, const Vec3& o, int n) {
  Rgb sum(0.0);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      // Cosine-weighted at the cells' midpoints, so each cell holds cos(theta) d(omega) = pi / n^2.
      const std::optional<Vec3> i = cosine_direction((a + 0.5) / n, (b + 0.5) / n);
      if (!i) continue;
      if (const auto f = brdf.eval(o, *i)) sum += *f;
    }
  return sum * (kPi / double(n * n));
}

std::vector<std::string> plausibility_warnings(const HalfDiffTable& table, const FitResult& fit) {
  std::vector<std::string> out;
  // Negative measurements, per channel.
  for (int c = 0; c < 3; ++c) {
    // Branch-free so that it vectorizes (a missing bin is NaN: it compares false both ways).
    std::size_t negative = 0, valid = 0;
    const float* v = table.channel(c);
#pragma omp simd reduction(+ : negative, valid)
    for (std::size_t n = 0; n < HalfDiffTable::kBins; ++n) {
      valid += std::size_t(v[n] == v[n]);
      negative += std::size_t(v[n] < 0.0f);
    }
    if (negative > 0)
      out.push_back(format("%.1f%% of the measured values are negative in the ", 100.0 * double(negative) / double(valid)) +
                    HalfDiffTable::channel_name(c) + " channel (noise around zero, kept as measurements)");
  }
  // The Fresnel curve of the tabulated representation.
  for (int j = 0; j < FresnelCurve::kSize; ++j) {
    const auto [c, v] = above(fit.fresnel().value[std::size_t(j)], 1.0);
    if (c < 0) continue;
    out.push_back(format("Fresnel factor above 1: %.3f at theta_d %.0f degrees", v, FresnelCurve::theta_d(j) * 180.0 / kPi) +
                  " (" + HalfDiffTable::channel_name(c) + "; first such angle)");
    break;
  }
  if (fit.refined)
    for (const RepresentationRow& r : kRepresentations) {  // the parametric fits (fit/representations.h)
      if (!r.parametric) continue;
      const auto [c0, f0] = above((fit.*r.parametric).f0, 1.0);
      const auto [c82, f82] = above((fit.*r.parametric).f82, 1.0);
      if (c0 >= 0) out.push_back(std::string(r.name) + format(" fit: f0 above 1 (%.3f, ", f0) + HalfDiffTable::channel_name(c0) + ")");
      if (c82 >= 0) out.push_back(std::string(r.name) + format(" fit: f82 above 1 (%.3f, ", f82) + HalfDiffTable::channel_name(c82) + ")");
    }
  // Directional albedo of the measurement and of the tabulated representation.
  const TabulatedMicrofacet model(fit.lobe.tables(fit.smith), {});
  for (const auto& [what, brdf] : {std::pair<const char*, const Brdf*>{"measurement", &table}, {"tabulated fit", &model}}) {
    for (const double degrees : {0.0, 30.0, 60.0, 80.0}) {
      const auto [c, v] = above(directional_albedo(*brdf, spherical_direction(degrees * kPi / 180.0, 0.0)), 1.0);
      if (c < 0) continue;
      out.push_back(std::string("directional albedo of the ") + what + format(" above 1: %.3f at theta %.0f degrees", v, degrees) +
                    " (" + HalfDiffTable::channel_name(c) + ")");
      break;
    }
  }
  return out;
}

}  // namespace facetfit
