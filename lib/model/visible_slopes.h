// The renderer's draw of a tabulated isotropic lobe's visible normals: in slope space, from tables, with
// no root to find.
//
// Seen from o = (sin theta_o, 0, cos theta_o), a facet of slopes (x~, y~) (normal h ~ (-x~, -y~, 1)) shows
// the area max(0, cos theta_o - x~ sin theta_o) per unit of projected area, so the visible slopes have the
// density (Heitz and d'Eon 2014)
//
//   P_o(x~, y~) ~ max(0, cos theta_o - x~ sin theta_o) P22(x~, y~),
//
// whose view enters through x~ alone: x~ is drawn from a marginal per view slice, then y~ from P22's
// conditional on x~, the same for every view. Both are piecewise constant on cells of the bounded slopes,
// drawn by inverting their running sums (core/piecewise_constant.h),
//
//   v = x~ / (c + |x~|) in (-1, 1),   w = |y~| / (c + |y~|) in [0, 1),
//
// c the lobe's E|x~| (its GGX alpha), so that the cells resolve any roughness, uniform within a cell, and
// y~'s sign drawn apart. Both view slices around cos(theta_o) are mixed linearly, as
// model/tabulated.h mixes its own. pdf() is this density exactly, per steradian of h:
//
//   p(h) = P(cell) / (dv dw of a cell) * dv/dx~ * dw/dy~ / 2 / cos^3(theta_h),
//   dv/dx~ = c / (c + |x~|)^2,   d(omega_h) = cos^3(theta_h) dx~ dy~.
//
// TabulatedMicrofacet draws the same lobe over (theta_h, phi_h), as the LUT's sampling rows and the OSL
// shaders do; its azimuth needs Newton steps on a(sin phi) + b phi, which this draw does without.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "core/vec.h"
#include "model/proposal.h"
#include "model/tabulated.h"
#include "model/tabulated_ndf.h"

namespace facetfit {

class VisibleSlopes {
 public:
  static constexpr int kCells = 128;      // cells of v over (-1, 1)
  static constexpr int kSideCells = 64;   // cells of w over [0, 1)
  static constexpr int kSlices = 33;      // view slices (view_slice())
  static constexpr int kGuide = 128;      // guide entries per row of running sums (append_cdf_guide)
  static constexpr double kEdge = 1.0 - 1e-12;  // |v| and w at most this: the slopes stay finite

  VisibleSlopes() = default;
  explicit VisibleSlopes(const TabulatedNdf& ndf);

  // A normal h seen from o (o.z > 0) from u1, u2 in [0, 1): u1 picks the view slice and x~, u2 the sign
  // and the size of y~.
  Vec3 sample(const Vec3& o, double u1, double u2) const;
  // Density of sample() per steradian of h (zero where h faces away from o).
  double pdf(const Vec3& o, const Vec3& h) const;

  double scale() const { return scale_; }  // c
  // The tables, for the SIMD kernels (render/tabulated_batch.h). Per view slice s, x~'s cells: their running
  // sums (kCells + 1 each, 0 to 1), masses (kCells) and guide (kGuide + 1, append_cdf_guide). Per x~ cell i
  // the same for y~'s conditional over w (kSideCells + 1, kSideCells, kGuide + 1).
  const std::vector<double>& view_cdf() const { return view_cdf_; }
  const std::vector<double>& view_mass() const { return view_mass_; }
  const std::vector<std::int64_t>& view_guide() const { return view_guide_; }
  const std::vector<double>& side_cdf() const { return side_cdf_; }
  const std::vector<double>& side_mass() const { return side_mass_; }
  const std::vector<std::int64_t>& side_guide() const { return side_guide_; }

 private:
  double scale_ = 1.0;
  std::vector<double> view_cdf_, view_mass_, side_cdf_, side_mass_;
  std::vector<std::int64_t> view_guide_, side_guide_;
};

// Where the view o (o.z >= 0) falls between the view slices: slice s and the weight t of slice s + 1.
// The slices are uniform in k = cos(theta_o) / (cos(theta_o) + c sin(theta_o)), the bounded place v of
// the slope x~ = cot(theta_o) where the view's horizon cuts the facets: a lobe narrower than the view's
// grazing angle keeps its slices apart.
struct ViewSlice {
  int s;
  double t;
};
inline ViewSlice view_slice(const Vec3& o, double scale) {
  const double cos_o = std::min(o.z, 1.0), sin_o = std::sqrt(std::max(0.0, 1.0 - cos_o * cos_o));
  const double x = cos_o / (cos_o + scale * sin_o) * (VisibleSlopes::kSlices - 1);
  const int s = std::min(int(x), VisibleSlopes::kSlices - 2);
  return {s, x - s};
}

// A tabulated lobe's proposal (model/proposal.h) with its visible normals drawn by VisibleSlopes: the
// parts (lobe, body, coat) and their weights are the lobe's own.
class VisibleSlopeProposal final : public Proposal {
 public:
  VisibleSlopeProposal(const TabulatedNdf& ndf, const ProposalParts& parts) : slopes_(ndf), parts_(parts) {}
  // The proposal of a lobe with these tables: its NDF, with its parts.
  explicit VisibleSlopeProposal(const MicrofacetTables& tables) : VisibleSlopeProposal(tables.ndf, tables.proposal_parts()) {}
  // The proposal of `lobe` (unstretched: a stretch reshapes the lobe, not these tables).
  static std::shared_ptr<const VisibleSlopeProposal> of(const TabulatedMicrofacet& lobe) {
    return std::make_shared<VisibleSlopeProposal>(lobe.tables());
  }

  std::optional<Vec3> sample_direction(const Vec3& o, double u1, double u2) const override;
  double pdf(const Vec3& o, const Vec3& i) const override;
  // The lobe's part alone, per steradian of i: reflection about h, d(omega_i) = 4 (o.h) d(omega_h).
  double lobe_pdf(const Vec3& o, const Vec3& i) const;

  const VisibleSlopes& slopes() const { return slopes_; }
  const ProposalParts& parts() const { return parts_; }

 private:
  VisibleSlopes slopes_;
  ProposalParts parts_;
};

}  // namespace facetfit
