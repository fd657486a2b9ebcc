// Back-scattering f(k, k) as a measurement holds it at its own nodes, when they are not a MERL table's
// bins: a UTIA file's diagonal nodes (theta_i = theta_v, phi_i = phi_v), six polar angles 15 degrees
// apart at 48 azimuths. The fits read it there rather than from a table resampled between them.
#pragma once

#include <vector>

#include "core/vec.h"

namespace facetfit {

struct BackscatterLattice {
  std::vector<double> theta;  // polar angles, increasing, radians
  int azimuths = 0;           // phi_k = 2 pi k / azimuths
  std::vector<Rgb> value;     // f at (theta[p], phi_k): value[p * azimuths + k], 1/sr

  bool empty() const { return value.empty(); }
  const Rgb& at(int p, int k) const { return value[std::size_t(p) * std::size_t(azimuths) + std::size_t(k)]; }
  // The mean over the azimuths at theta[p]: an isotropic fit's back-scattering.
  Rgb azimuthal_mean(int p) const {
    Rgb sum(0.0);
    for (int k = 0; k < azimuths; ++k) sum += at(p, k);
    return sum / double(azimuths);
  }
};

}  // namespace facetfit
