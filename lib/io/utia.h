// UTIA anisotropic BRDF database files (Filip & Vavra 2014, "Template-Based Sampling of Anisotropic
// BRDFs"; http://btf.utia.cas.cz): raw float64, 3 planes (R, G, B) x 6 theta_i (0, 15, ..., 75 degrees)
// x 48 phi_i (7.5 degree steps from 0) x 6 theta_v x 48 phi_v, plane-major, then theta_i, phi_i,
// theta_v, phi_v; i the illumination, v the view direction.
//
// Values are sRGB-encoded: x > 0.0375 decodes as ((x + 0.055) / 1.055)^2.4, else x / 12.92, and the
// decoded value times 100 is the BRDF in 1/sr, as the issue describes the database's reader (the
// readers published beside the data return the raw numbers). The scale could not be checked against a
// real file here (none can be fetched): the writer encodes f / 100 so that facetfit's own files read
// back to the BRDF they were written from (tests/io/test_utia.cpp); negative entries (noise) decode
// linearly and are kept, as for RGL.
//
// Between the nodes eval() is quadrilinear in (theta_i, phi_i, theta_v, phi_v) degrees, periodic in the
// azimuths, and extrapolates linearly past 75 degrees from the last interval: the readers published
// with the database do exactly this.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/brdf.h"
#include "io/backscatter_lattice.h"
#include "io/merl.h"

namespace facetfit {

class UtiaBrdf final : public Brdf, public SelfTabulating {
 public:
  static constexpr int kTheta = 6, kPhi = 48;
  static constexpr double kThetaStep = 15.0, kPhiStep = 7.5;  // degrees
  static constexpr std::size_t kPerPlane = std::size_t(kTheta) * kPhi * kTheta * kPhi;
  static constexpr std::size_t kFileBytes = 3 * kPerPlane * sizeof(double);

  // Throws Error("<path>: <problem>") for anything that is not a complete, finite UTIA file.
  static UtiaBrdf read(const std::string& path);
  // Samples any BRDF at the nodes (what the writer writes).
  static UtiaBrdf tabulate(const Brdf& brdf);
  // f(k, k) at the diagonal nodes (theta_i = theta_v, phi_i = phi_v): six polar angles, 48 azimuths.
  BackscatterLattice backscatter() const;
  // The file's mean over turns of both directions about the normal by multiples of its azimuth step, as
  // a file of its own (isotropic): node (ti, pi, tv, pv) becomes the mean over k of node (ti, pi + k,
  // tv, pv + k), which depends on pv - pi alone. The interpolation being linear in the nodes, its eval()
  // is the mean of eval() over those 48 turns, at the cost of one: what an isotropic fit sees of an
  // anisotropic material.
  UtiaBrdf azimuthal_mean() const;
  // The nodes with phi_i = 0, each with the solid angles of the two nodes' cells (a polar cap at
  // theta = 0): every node an isotropic file (azimuthal_mean()) holds, up to a turn about the normal.
  std::vector<MeasuredSample> samples_at_first_azimuth() const;
  // Every node pair (82,944), weighted the same way: what the file measured, for anisotropic fits.
  std::vector<MeasuredSample> samples() const;
  // The table the fits read: the azimuthal mean (the isotropic fits see that; fit/extract_2d.h fits the
  // file itself), with the nodes it was measured at (the mean's, for the isotropic fits' distances; every
  // node, for the anisotropic ones) and its back-scattering at its own nodes.
  HalfDiffTable table() const override;
  // Writes the file through a temporary; throws Error naming the file.
  void write(const std::string& path) const;

  std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const override;
  // f at node (theta_i, phi_i, theta_v, phi_v) indices, 1/sr.
  Rgb node(int theta_i, int phi_i, int theta_v, int phi_v) const;

  static double decode(double x);  // file value -> f (1/sr)
  static double encode(double f);  // f (1/sr) -> file value

 private:
  explicit UtiaBrdf(std::shared_ptr<const std::vector<double>> f) : f_(std::move(f)) {}
  static std::size_t index(int theta_i, int phi_i, int theta_v, int phi_v) {
    return ((std::size_t(theta_i) * kPhi + phi_i) * kTheta + theta_v) * kPhi + phi_v;
  }
  std::shared_ptr<const std::vector<double>> f_;  // decoded, plane-major; immutable, shared by copies
};

}  // namespace facetfit
