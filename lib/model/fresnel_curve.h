// The tabulated RGB Fresnel curve of the tabulated microfacet model: one RGB factor per degree of
// theta_d (fit/fresnel_fit.h fits it).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/vec.h"

namespace facetfit {

struct FresnelCurve {
  static constexpr int kSize = 90;  // entry j at theta_d = j pi/180: MERL's theta_d bins

  std::vector<Rgb> value = std::vector<Rgb>(kSize, Rgb(0.0));
  // Measurements that went into each entry, per channel; an entry with none is interpolated.
  std::vector<std::array<std::int64_t, 3>> count = std::vector<std::array<std::int64_t, 3>>(kSize);

  static double theta_d(int j) { return j * (0.5 * kPi / kSize); }
  // Linear between entries; past the last entry (89 degrees) the last value.
  Rgb eval(double theta_d) const;
};

}  // namespace facetfit
