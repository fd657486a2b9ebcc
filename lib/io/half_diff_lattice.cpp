#include "io/half_diff_lattice.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>

#include "core/frame.h"
#include "core/halfdiff.h"

namespace facetfit {

double HalfDiffLattice::theta_h(int h) {
  const double u = (h + 0.5) / kThetaH;
  return 0.5 * kPi * u * u;
}
double HalfDiffLattice::phi_h(int ph) { return 2.0 * kPi * (ph + 0.5) / kPhiH; }
double HalfDiffLattice::theta_d(int d) { return 0.5 * kPi * (d + 0.5) / kThetaD; }
double HalfDiffLattice::phi_d(int pd) { return 2.0 * kPi * (pd + 0.5) / kPhiD; }

double HalfDiffLattice::measure(int h, int d) {
  // theta_h = (pi/2) u^2: dtheta_h = pi u du.
  const double u = (h + 0.5) / kThetaH, t_d = theta_d(d);
  const double d_theta_h = kPi * u / kThetaH, d_phi_h = 2.0 * kPi / kPhiH;
  const double d_theta_d = 0.5 * kPi / kThetaD, d_phi_d = 2.0 * kPi / kPhiD;
  return 4.0 * std::cos(t_d) * std::sin(t_d) * std::sin(theta_h(h)) * d_theta_h * d_phi_h * d_theta_d * d_phi_d;
}

std::pair<Vec3, Vec3> HalfDiffLattice::directions(int h, int ph, int d, int pd) {
  const auto [o, i] = from_half_diff(theta_h(h), theta_d(d), phi_d(pd));
  const TurnedFrame half(phi_h(ph));  // the pair at phi_h = 0, turned to the half vector's azimuth
  return {half.from_frame(o), half.from_frame(i)};
}

HalfDiffLattice HalfDiffLattice::of(const Brdf& source) {
  HalfDiffLattice lattice;
  lattice.value.assign(kSize, Rgb(std::numeric_limits<double>::quiet_NaN()));
  tbb::parallel_for(0, kThetaH * kPhiH, [&](int hp) {
    const int h = hp / kPhiH, ph = hp % kPhiH;
    for (int d = 0; d < kThetaD; ++d)
      for (int pd = 0; pd < kPhiD; ++pd) {
        const auto [o, i] = directions(h, ph, d, pd);
        if (i.z <= 1e-6 || o.z <= 1e-6) continue;
        if (const auto f = source.eval(o, i)) lattice.value[index(h, ph, d, pd)] = *f;
      }
  });
  return lattice;
}

}  // namespace facetfit
