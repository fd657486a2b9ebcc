#include "model/visible_slopes.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/frame.h"
#include "core/piecewise_constant.h"
#include "core/quadrature_rules.h"

namespace facetfit {

namespace {

constexpr int kCells = VisibleSlopes::kCells, kSide = VisibleSlopes::kSideCells, kSlices = VisibleSlopes::kSlices;

// The shares of `weight` (n cells) into mass, their running sums into cdf[0..n] (0 to 1) and a guide to
// them; a row without weight is uniform (its draws still terminate; where it is reached no facet is
// visible).
void append_row(const double* weight, int n, std::vector<double>& cdf, std::vector<double>& mass, std::vector<std::int64_t>& guide) {
  double total = 0.0;
  for (int k = 0; k < n; ++k) total += weight[k];
  const bool flat = !(total > 0.0);
  const std::size_t first = cdf.size();
  cdf.push_back(0.0);
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    mass.push_back(flat ? 1.0 / n : weight[k] / total);
    sum += flat ? 1.0 : weight[k];
    cdf.push_back(flat ? sum / n : sum / total);
  }
  cdf.back() = 1.0;
  append_cdf_guide(cdf.data() + first, n, VisibleSlopes::kGuide, guide);
}

}  // namespace

VisibleSlopes::VisibleSlopes(const TabulatedNdf& ndf) {
  // c = E|x~| = 4 integral of sin^2(theta) D d(theta) (|x~| = tan(theta) |cos(phi)|), Gauss points on the
  // grid's intervals (theta = u^2 pi / 2, d(theta) = pi u du).
  std::vector<double> gx, gw;
  gauss_legendre(4, gx, gw);
  const int r = ndf.grid.resolution;
  double moment = 0.0;
  for (int j = 0; j < r; ++j)
    for (std::size_t q = 0; q < gx.size(); ++q) {
      const double u = (j + gx[q]) / r, theta = ThetaGrid::theta_of_u(u), s = std::sin(theta);
      moment += 4.0 * s * s * ndf.D(theta) * gw[q] / r * kPi * u;
    }
  scale_ = std::isfinite(moment) && moment > 0.0 ? clamp(moment, 1e-4, 100.0) : 1.0;

  // P22 over the cells of v >= 0 (those of v < 0 mirror them) at 3 x 3 Gauss points: each point's
  // weight is P22 dx~/dv dy~/dw times the cell's area in (v, w).
  constexpr int kPoints = 3;
  gauss_legendre(kPoints, gx, gw);
  const int half = kCells / 2;
  const double c = scale_;
  std::vector<double> side(std::size_t(half) * kSide, 0.0), point(std::size_t(half) * kPoints, 0.0), slope(point.size());
  tbb::parallel_for(0, half, [&](int a) {
    for (int q = 0; q < kPoints; ++q) {
      const double v = (a + gx[std::size_t(q)]) * 2.0 / kCells, x = c * v / (1.0 - v), dx = c / ((1.0 - v) * (1.0 - v));
      slope[std::size_t(a) * kPoints + q] = x;
      for (int j = 0; j < kSide; ++j)
        for (int p = 0; p < kPoints; ++p) {
          const double w = (j + gx[std::size_t(p)]) / kSide, y = c * w / (1.0 - w), dy = c / ((1.0 - w) * (1.0 - w));
          const double weight = ndf.slope_pdf(std::atan(std::sqrt(x * x + y * y))) * dx * dy * gw[std::size_t(q)] *
                                gw[std::size_t(p)] * (2.0 / kCells) / kSide;
          side[std::size_t(a) * kSide + j] += weight;
          point[std::size_t(a) * kPoints + q] += weight;
        }
    }
  });
  const auto mirror = [half](int i) { return i >= half ? i - half : half - 1 - i; };

  // y~ given x~'s cell: the same for every view.
  for (int i = 0; i < kCells; ++i) append_row(side.data() + std::size_t(mirror(i)) * kSide, kSide, side_cdf_, side_mass_, side_guide_);
  // x~ per view slice: P22's marginal at each Gauss point times the area the view sees of it.
  std::vector<double> weight(kCells);
  for (int s = 0; s < kSlices; ++s) {
    // k = s / (kSlices - 1) (view_slice): cot(theta_o) = k c / (1 - k).
    const double k = double(s) / (kSlices - 1), theta_o = std::atan2(1.0 - k, k * c);
    const double cos_o = std::cos(theta_o), sin_o = std::sin(theta_o);
    for (int i = 0; i < kCells; ++i) {
      const int a = mirror(i);
      const double sign = i >= half ? 1.0 : -1.0;
      weight[std::size_t(i)] = 0.0;
      for (int q = 0; q < kPoints; ++q)
        weight[std::size_t(i)] += point[std::size_t(a) * kPoints + q] * std::max(0.0, cos_o - sign * slope[std::size_t(a) * kPoints + q] * sin_o);
    }
    append_row(weight.data(), kCells, view_cdf_, view_mass_, view_guide_);
  }
}

Vec3 VisibleSlopes::sample(const Vec3& o, double u1, double u2) const {
  if (!above_horizon(o)) return {0.0, 0.0, 1.0};  // no view slice (callers draw for o above the horizon)
  // One of the two view slices around o with the weights of the mixture, reusing u1.
  const ViewSlice view = view_slice(o, scale_);
  const int s = view.s + pick_of_two(view.t, &u1);
  double tx, ty;
  const int i = sample_cdf(view_cdf_.data() + std::size_t(s) * (kCells + 1), kCells, u1, &tx);
  const double v = clamp(-1.0 + 2.0 * (i + tx) / kCells, -kEdge, kEdge);
  const double x = scale_ * v / (1.0 - std::abs(v));
  // y~'s sign from u2's first half, its size from the rest.
  const double sign = u2 < 0.5 ? -1.0 : 1.0;
  u2 = u2 < 0.5 ? 2.0 * u2 : 2.0 * u2 - 1.0;
  const int j = sample_cdf(side_cdf_.data() + std::size_t(i) * (kSide + 1), kSide, u2, &ty);
  const double w = std::min((j + ty) / kSide, kEdge);
  const double y = sign * (scale_ * w / (1.0 - w));
  const double inv = 1.0 / std::sqrt(1.0 + x * x + y * y);
  // From o's azimuth frame to the local one.
  return TurnedFrame::of_azimuth(o).from_frame(Vec3(-x * inv, -y * inv, inv));
}

double VisibleSlopes::pdf(const Vec3& o, const Vec3& h) const {
  if (!above_horizon(o, h) || glm::dot(o, h) <= 0.0) return 0.0;
  // h in o's azimuth frame; with A = c cos(theta_h) + |h_x| (and B for y), v = x~ / (c + |x~|) = -h_x / A,
  // w = |h_y| / B, and dv/dx~ dw/dy~ / cos^3(theta_h) = c^2 cos(theta_h) / (A B)^2: no slope, so no
  // overflow, at a grazing h.
  const Vec3 seen = TurnedFrame::of_azimuth(o).to_frame(h);
  const double hx = seen.x, hy = seen.y;
  const double a = scale_ * h.z + std::abs(hx), b = scale_ * h.z + std::abs(hy);
  const double v = -hx / a, w = std::abs(hy) / b;
  const int i = std::clamp(int((v + 1.0) * (0.5 * kCells)), 0, kCells - 1), j = std::min(int(w * kSide), kSide - 1);
  const ViewSlice view = view_slice(o, scale_);
  const double* mass = view_mass_.data() + std::size_t(view.s) * kCells + i;
  const double cell = ((1.0 - view.t) * mass[0] + view.t * mass[kCells]) * side_mass_[std::size_t(i) * kSide + j];
  // Per unit of (v, w): the cell's share over its area (2 / kCells) (1 / kSide), half on each sign of y~.
  return cell * (0.25 * kCells * kSide) * (scale_ * scale_ * h.z) / ((a * b) * (a * b));
}

std::optional<Vec3> VisibleSlopeProposal::sample_direction(const Vec3& o, double u1, double u2) const {
  if (!above_horizon(o)) return std::nullopt;
  return parts_.sample(o, u1, u2, [&](double a, double b) -> std::optional<Vec3> {
    const Vec3 h = slopes_.sample(o, a, b);
    const Vec3 i = reflect_about(o, h);
    if (i.z <= 0.0) return std::nullopt;
    return i;
  });
}

double VisibleSlopeProposal::lobe_pdf(const Vec3& o, const Vec3& i) const {
  if (i.z <= 0.0 || o.z <= 0.0) return 0.0;
  const Vec3 h = glm::normalize(o + i);
  const double oh = glm::dot(o, h);
  if (oh <= 0.0) return 0.0;
  return slopes_.pdf(o, h) / (4.0 * oh);
}

double VisibleSlopeProposal::pdf(const Vec3& o, const Vec3& i) const {
  if (i.z <= 0.0 || o.z <= 0.0) return 0.0;
  return parts_.pdf(o, i, lobe_pdf(o, i));
}

}  // namespace facetfit
