// The RGB Fresnel curve: at each theta_d, the mean ratio of the measurement to the ideal-mirror
// microfacet model (the extracted D and G with F = 1).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "fit/tabulated_ndf.h"
#include "io/merl.h"
#include "model/smith.h"

namespace facetfit {

struct FresnelCurve {
  static constexpr int kSize = MerlTable::kThetaD;  // entry j at theta_d = j pi/180, as MERL's theta_d bins

  std::vector<Rgb> value = std::vector<Rgb>(kSize, Rgb(0.0));
  // Measurements that went into each entry, per channel; an entry with none is interpolated.
  std::vector<std::array<std::int64_t, 3>> count = std::vector<std::array<std::int64_t, 3>>(kSize);

  static double theta_d(int j) { return MerlTable::theta_d(j); }
  // Linear between entries; past the last entry (89 degrees) the last value.
  Rgb eval(double theta_d) const;
};

// One pass over every valid bin of the table. Each theta_d entry is the mean of the ratios
// measurement / model weighted by the model: sum(measurement) / sum(model). The unweighted mean is
// dominated by the bins where the F = 1 model is nearly zero, i.e. by noise and by what is not
// microfacet reflection. Sets `problem` when no bin holds a usable measurement.
FresnelCurve fit_fresnel(const MerlTable& table, const TabulatedNdf& ndf, Smith smith, std::string* problem);

}  // namespace facetfit
