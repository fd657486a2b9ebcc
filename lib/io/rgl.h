// RGL EPFL material database `.bsdf` files: Dupuy & Jakob 2018, "An Adaptive Parameterization for
// Efficient Material Acquisition and Rendering" (the tensor files read by Mitsuba's `measured` BSDF).
//
// The measurement is not stored per direction pair: for each incident elevation theta_i it is stored
// on a 2D "sample space" [0,1]^2 that the material's own visible-normal distribution (VNDF) warps onto
// half vectors. Evaluating f(i, o) therefore inverts that warp: h = normalize(i + o) in the unit
// coordinates u = (sqrt(theta_h / (pi/2)), (phi_h - phi_i + pi) / 2pi) is mapped back to the sample
// (s0, s1) whose warp lands on it, and the RGB table is read there. Following Mitsuba's `measured`
// eval (and RGL's reference loader powitacq_rgb), the product
//
//   rgb(theta_i, s) * ndf(u_h) / (4 sigma(u_i))  =  f(i, o) cos(theta_o)
//
// already contains the cosine of the direction that is not the table parameter, so f is that product
// divided by cos(theta_o). The file's theta_i axis is indexed by our i (toward the light). Mitsuba's
// renderer puts its camera-side direction there instead; a reciprocal material cannot tell the two
// apart, and the measured files are reciprocal to within a few percent (tests/test_rgl.cpp).
//
// Only isotropic files (phi_i with a single entry) are supported. Negative (out-of-gamut) RGB values
// of the colour-converted spectra are clipped to zero, as powitacq_rgb does.
#pragma once

#include <memory>
#include <string>

#include "core/brdf.h"

namespace facetfit {

class RglBsdf final : public Brdf {
 public:
  // Throws Error("<path>: <problem>") for anything that is not a complete, consistent, finite,
  // isotropic RGB tensor file. Every size in the header is checked before it is trusted.
  static RglBsdf read(const std::string& path);

  // f(i, o) in 1/sr, RGB; zero when either direction is not strictly above the horizon. The table
  // covers the whole hemisphere, so there is always an answer.
  std::optional<Rgb> eval(const Vec3& i, const Vec3& o) const override;

  // The `description` field: material name and provider.
  const std::string& description() const;

  // The file's own measured NDF D(theta_h), per steradian, phi-averaged, renormalized so that
  // integral D cos(theta) d(omega) over the hemisphere is exactly 1 under this interpolation
  // (the stored tables integrate to about 1.008). Zero outside [0, pi/2].
  double measured_ndf(double theta) const;

  // integral D cos(theta) d(omega) of the stored `ndf` table before that renormalization.
  double measured_ndf_stored_integral() const;

  // The `jacobian` flag: whether the RGB table is to be multiplied by ndf / (4 sigma).
  bool jacobian() const;

 private:
  struct Tables;
  explicit RglBsdf(std::shared_ptr<const Tables> tables);

  // Immutable once read: copies share it, and const eval needs no locking.
  std::shared_ptr<const Tables> t_;
};

}  // namespace facetfit
