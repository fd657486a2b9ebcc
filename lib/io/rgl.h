// RGL EPFL material database `.bsdf` files: Dupuy & Jakob 2018, "An Adaptive Parameterization for
// Efficient Material Acquisition and Rendering" (the tensor files of Mitsuba's `measured` BSDF).
//
// The measurement is not stored per direction pair. For each elevation theta_i of one direction p it
// lives on a "sample square" [0,1]^2 that the material's own visible-normal distribution (VNDF)
// warps onto half vectors. So evaluating T(p, q) inverts that warp: the half vector h of p and q, in
// the unit coordinates u = (sqrt(theta_h / (pi/2)), (phi_h - phi_p + pi) / 2pi), goes back to the
// point s of the square whose warp lands on it, and the RGB table is read at s, linearly between
// the two bracketing theta_i slices. As in Mitsuba's `measured` eval and RGL's powitacq_rgb loader,
//
//   T(p, q) = rgb(theta_p, s) * ndf(u_h) / (4 sigma(u_p))  =  f(p, q) cos(theta_q),
//
// the cosine being that of the direction which does not pick the slices (powitacq_rgb documents its
// eval as "f_r * cos"; the data agree: dividing by the other cosine instead breaks reciprocity by
// ~90%, and the white paper's albedo comes out 0.82 at normal incidence, f = 0.28/sr).
//
// This parameterization is checked against the files themselves: the acquisition derives `sigma`
// and `vndf` from `ndf`, and under the maps above (node-centred grids, theta along the last axis)
// they agree to 5e-4 and 1e-7 on the database files (self_consistency). The retro-reflection in the
// `rgb` table, however, does not reproduce `ndf` through the 2015 power iteration (docs/accuracy.md):
// the acquisition measured `ndf` separately, and the files do not say how.
//
// Anisotropic files (phi_i with more than two entries, Mitsuba's test) hold slices over (phi_i, theta_i),
// blended bilinearly between the bracketing ones, and measure the half vector's azimuth absolutely; a
// phi_i span of pi or pi/2 declares a half-turn or two-mirror symmetry, and directions are carried
// into the span first, as Mitsuba does. Negative RGB values (measurement
// noise around zero, out-of-gamut colour of the converted spectra) are kept, as Mitsuba's `measured`
// does: clipping them biases dark channels upward (docs/conventions.md).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/brdf.h"
#include "io/backscatter_lattice.h"
#include "io/merl.h"

namespace facetfit {

class RglBsdf final : public Brdf, public OneSidedMeasurement, public SelfTabulating {
 public:
  // Throws Error("<path>: <problem>") for anything that is not a complete, consistent, finite RGB
  // tensor file. Every size in the header is checked before it is trusted.
  static RglBsdf read(const std::string& path);

  // Which direction picks the theta_i slices. A one-sided estimate divides T by a cosine that
  // vanishes at the horizon, where the tables' interpolation floor (about 1% of the diffuse level)
  // becomes spikes of hundreds per steradian. The default weighs the two one-sided estimates by
  // those cosines: bounded unless both directions graze, and reciprocal by construction.
  enum class Slices {
    symmetric,  // both: (T(i,o) + T(o,i)) / (cos i + cos o); reciprocal, bounded unless both graze
    light,      // i, as the file's name theta_i suggests: T(i,o) / cos o
    view,       // o, as Mitsuba renders it (its wi is the camera side): T(o,i) / cos i
  };

  // f(o, i) in 1/sr, RGB; zero when either direction is not strictly above the horizon. The table
  // covers the whole hemisphere, so there is always an answer.
  std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const override;
  // T(p, q) from the slices of p, as eval's one-sided modes read it (without their division by cos q);
  // nullopt where theta_p is past the last slice below 90 degrees: the file's slice at the horizon is
  // no measurement (no instrument lights or views a surface there), so in between the value is
  // interpolated toward it. On paper_white the two one-sided estimates of f agree within 4% with p up
  // to that slice (78.5 degrees) and part by 27% at 86 degrees, 2.5x at 89 (docs/extraction.md).
  std::optional<Rgb> one_sided(const Vec3& p, const Vec3& q) const override;
  // The elevation of that slice (the largest theta_i below pi/2), radians.
  double measured_elevation_limit() const;

  Slices slices() const { return slices_; }
  void set_slices(Slices slices) { slices_ = slices; }

  // The `description` field: material name and provider.
  const std::string& description() const;

  // The file's own measured NDF D(theta_h), per steradian, phi-averaged, renormalized so that
  // integral D cos(theta) d(omega) over the hemisphere is exactly 1 under this interpolation
  // (the stored tables integrate to about 1.008). Zero outside [0, pi/2].
  double measured_ndf(double theta) const;

  // integral D cos(theta) d(omega) of the stored `ndf` table before that renormalization.
  double measured_ndf_stored_integral() const;

  // The file's `sigma` field at elevation theta, phi-averaged: the projected area
  // integral max(0, k.h) D(h) dw_h of the NDF, which the acquisition computed from its `ndf` and
  // scaled to sigma(0) = 1, i.e. the sigma of measured_ndf (self_consistency checks it). Zero outside
  // [0, pi/2].
  double measured_sigma(double theta) const;

  // The incident elevations theta_i of the file's slices, increasing. Only at these angles does the
  // RGB table hold a measurement of a given configuration; in between, eval blends two slices.
  const std::vector<double>& slice_elevations() const;
  // Whether the file is anisotropic (its slices span incident azimuths too).
  bool anisotropic() const;

  // Back-scattering f(k, k) on `thetas` polar angles, at the middle of equal steps up to 89.5 degrees,
  // times `azimuths` azimuths: what an anisotropic fit reads (fit/extract_2d.h).
  BackscatterLattice backscatter(int thetas, int azimuths) const;
  // The table the fits read: the reciprocal blend of the two one-sided estimates, with the file itself as
  // the table's source_one_sided (the fits' distances read each estimate where it was measured,
  // fit/measurement.h); for an anisotropic file its azimuthal mean, with its back-scattering at 90 x 64
  // nodes and its lattice over the half vector's azimuth.
  HalfDiffTable table() const override;

  // How well the file's tables agree with each other under this reader's parameterization (the
  // theta -> u = sqrt(theta / (pi/2)) and phi -> (phi - phi_i + pi) / 2pi maps, node-centred grids,
  // theta along the last axis). The acquisition derives `sigma` and `vndf` from `ndf`, so a reader
  // that maps any of these axes wrongly sees them disagree; on the database files both errors are
  // below 1e-3. These checks cannot see the RGB table, which the acquisition measured separately.
  struct Consistency {
    // Largest relative difference, over the nodes of `sigma`, between the field and
    // integral max(0, k.h) measured_ndf(h) dw_h computed here.
    double sigma_error = 0.0;
    // Largest total-variation distance, over the theta_i slices, between the `vndf` table and
    // D(m) max(0, i.m) sin(theta_m) u_theta (the visible normals times the Jacobian of the unit
    // square), both normalized over the same nodes; 0 is identical, 1 disjoint.
    double vndf_error = 0.0;
  };
  Consistency self_consistency() const;

  // The `jacobian` flag: whether the RGB table is to be multiplied by ndf / (4 sigma).
  bool jacobian() const;

 private:
  struct Tables;
  explicit RglBsdf(std::shared_ptr<const Tables> tables);
  // T(p, q) = f(p, q) cos(theta_q) from the slices of direction p; both above the horizon, unit.
  Rgb table_value(const Vec3& p, const Vec3& q) const;

  // Immutable once read: copies share it, and const eval needs no locking.
  std::shared_ptr<const Tables> t_;
  Slices slices_ = Slices::symmetric;
};

// "view", "symmetric" or "light"; nullopt otherwise.
std::optional<RglBsdf::Slices> parse_slices(const std::string& name);

}  // namespace facetfit
