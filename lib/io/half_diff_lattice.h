// An anisotropic source's BRDF at nodes of the half/difference parameterization with the half vector's
// azimuth kept: what the fits of its anisotropic representations measure themselves against
// (fit/measurement.h; an anisotropic RGL file read through its evaluation: a UTIA file is fitted at its
// own node pairs instead). A MERL-layout table holds a BRDF's dependence on (theta_h, theta_d, phi_d) alone;
// an anisotropic material depends on phi_h as well.
//
// Nodes at cell centres: theta_h spaced as MERL's bins (theta_h = (pi/2) u^2, finer near the specular
// peak), phi_h and phi_d over a whole turn (phi_d + pi swaps the directions, and an RGL file is not
// reciprocal), theta_d uniform. 30 x 24 x 12 x 16 = 138k pairs, 3.3 MB.
#pragma once

#include <cstddef>
#include <vector>

#include "core/brdf.h"

namespace facetfit {

struct HalfDiffLattice {
  static constexpr int kThetaH = 30, kPhiH = 24, kThetaD = 12, kPhiD = 16;
  static constexpr std::size_t kSize = std::size_t(kThetaH) * kPhiH * kThetaD * kPhiD;

  // f(o, i) per node; a channel the source does not give is NaN. Empty: no lattice.
  std::vector<Rgb> value;

  bool empty() const { return value.empty(); }
  static std::size_t index(int h, int ph, int d, int pd) {
    return ((std::size_t(h) * kPhiH + std::size_t(ph)) * kThetaD + std::size_t(d)) * kPhiD + std::size_t(pd);
  }
  static double theta_h(int h);
  static double phi_h(int ph);
  static double theta_d(int d);
  static double phi_d(int pd);
  // The cell's measure in (theta_h, phi_h, theta_d, phi_d), 4 cos(theta_d) sin(theta_d) sin(theta_h)
  // dtheta_h dphi_h dtheta_d dphi_d (the Jacobian of the parameterization) at its centre.
  static double measure(int h, int d);
  // The node's directions (o, i); either may lie below the horizon.
  static std::pair<Vec3, Vec3> directions(int h, int ph, int d, int pd);

  // The source at every node (both directions above the horizon; other nodes NaN), in parallel.
  static HalfDiffLattice of(const Brdf& source);
};

}  // namespace facetfit
