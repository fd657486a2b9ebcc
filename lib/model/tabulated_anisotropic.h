// An anisotropic microfacet lobe from a tabulated NDF D(theta, phi): the 2D extraction's result
// (fit/extract_2d.h) as a BRDF that renders, with visible-normal sampling.
//
//   f(o, i) = F(o.h) D(h) G2(o, i) / (4 cos(theta_o) cos(theta_i)),   Lambda(w) = sigma(w) / cos(theta_w) - 1,
//
// sigma(w) = integral max(0, w.h) D(h) dw_h the projected area, tabulated beside D (Smith: the
// masking of a direction depends on the NDF only through its projected area). Both tables hold values at
// the extraction grid's polar nodes (model/theta_grid.h) times `phi_count` azimuths phi_m = 2 pi m / M;
// between them the grid's spline in u along theta and the same spline along phi, periodic.
//
// Visible normals h ~ D(h) max(0, o.h) depend on both angles of o. They are tabulated at view nodes
// (10 polar angles up to 85 degrees times 12 azimuths), each a piecewise-constant density over cells of
// the grid (polar intervals x azimuths, uniform in solid angle within a cell); a view between nodes draws
// from the mixture of its four bracketing nodes, bilinear weights, and pdf() is that mixture's density,
// so sampling and pdf agree exactly while the mixture only approximates the view's own distribution.
//
// A stretch (model/stretch.h) scales the lobe's slopes along its own axes (the tables' `axis`) and turns
// it by the stretch's rotation, as Closures::stretched does a closure lobe (model/closures.h) and the
// material shader its lobes (osl/facetfit_material.osl): a rotation alone turns the lobe.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "core/brdf.h"
#include "core/piecewise_constant.h"
#include "model/fresnel_curve.h"
#include "model/proposal.h"
#include "model/smith.h"
#include "model/stretch.h"
#include "model/theta_grid.h"

namespace facetfit {

struct AnisotropicTables {
  ThetaGrid grid;
  int phi_count = 0;
  std::vector<double> ndf;    // D(theta_j, phi_m), [j * phi_count + m], 1/sr
  std::vector<double> sigma;  // sigma at the direction (theta_j, phi_m)
  Smith smith = Smith::correlated;
  FresnelCurve fresnel;
  double axis = 0.0;  // the lobe's x axis, radians from the tangent (its anisotropic GGX fit's): a stretch scales along it
};

class TabulatedAnisotropic final : public Brdf, public Proposal {
 public:
  // Throws Error when the tables' sizes disagree or D has no mass.
  explicit TabulatedAnisotropic(AnisotropicTables tables, Stretch stretch = {});

  std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const override;

  using Sample = BrdfSample;
  // A light direction i for the view o from two uniform numbers in [0, 1); nullopt when o is at or below
  // the horizon or the reflection of o about the drawn normal is.
  std::optional<Sample> sample(const Vec3& o, double u1, double u2) const;
  // Density of sample() per steradian of i; over the upper hemisphere it integrates to the fraction of
  // draws that land there.
  double pdf(const Vec3& o, const Vec3& i) const override;
  std::optional<Vec3> sample_direction(const Vec3& o, double u1, double u2) const override;

  // Of the (stretched) lobe.
  double D(const Vec3& h) const;
  double lambda(const Vec3& w) const;
  double g1(const Vec3& w) const { return w.z > 0.0 ? 1.0 / (1.0 + lambda(w)) : 0.0; }
  // Density of the drawn normals per steradian of h.
  double visible_normal_pdf(const Vec3& o, const Vec3& h) const;

  const AnisotropicTables& tables() const { return shared_->tables; }
  const Stretch& stretch() const { return stretch_; }
  // The same lobe under another stretch: shares the tables, cheap enough per shading point.
  TabulatedAnisotropic stretched(const Stretch& stretch) const;

 private:
  static constexpr int kViewThetas = 10, kViewPhis = 12;
  static constexpr double kViewThetaMax = 85.0 * kPi / 180.0;

  // What a stretch does not change, immutable and shared between copies.
  struct Shared {
    AnisotropicTables tables;
    std::vector<PiecewiseConstant2D> views;  // [theta node * kViewPhis + phi node]
  };
  std::shared_ptr<const Shared> shared_;
  Stretch stretch_;
  Stretch scale_;     // the stretch's scales along the lobe's axes turned by its rotation
  TurnedFrame axis_;  // the measured lobe's axes

  // The measured (unstretched) lobe, in the tangent frame.
  double lookup(const std::vector<double>& table, const Vec3& w) const;  // spline in u and, periodic, phi
  double measured_D(const Vec3& h) const;
  double measured_lambda(const Vec3& w) const;
  double measured_visible_normal_pdf(const Vec3& o, const Vec3& h) const;
  Vec3 measured_visible_normal(const Vec3& o, double u1, double u2) const;
  // A direction or normal of the stretched lobe as the measured lobe sees it, tangent frame to tangent
  // frame: into the turned lobe's axes (the frame of `scale_`), scaled back, out of the measured lobe's.
  Vec3 measured_direction(const Vec3& w) const { return axis_.from_frame(scale_.direction(scale_.to_frame(w))); }
  Vec3 measured_normal(const Vec3& h) const { return axis_.from_frame(scale_.measured_normal(scale_.to_frame(h))); }
  Vec3 stretched_normal(const Vec3& m) const { return scale_.from_frame(scale_.stretched_normal(axis_.to_frame(m))); }
  // The (up to four) view nodes bracketing o and their weights.
  struct ViewBlend {
    int view[4];
    double weight[4];
  };
  ViewBlend blend(const Vec3& o) const;
  // Cell of h: polar interval j (row) and azimuth x (column); its solid angle.
  void cell_of(const Vec3& h, int* x, int* y) const;
  double cell_solid_angle(int y) const;
};

}  // namespace facetfit
