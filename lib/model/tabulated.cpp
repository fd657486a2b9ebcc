#include "model/tabulated.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/frame.h"
#include "core/piecewise_constant.h"
#include "core/quadrature_rules.h"
#include "model/visible_azimuth.h"

namespace facetfit {

VisibleNormalTables VisibleNormalTables::build(const TabulatedNdf& ndf) {
  const ThetaGrid& grid = ndf.grid;
  const int r = grid.resolution, n = grid.size();
  // D sin(theta) d(theta) at Gauss points of every interval: the slices only differ by the phi integral.
  constexpr int kPoints = 8;
  std::vector<double> gx, gw;
  gauss_legendre(kPoints, gx, gw);
  std::vector<double> sin_t(std::size_t(r) * kPoints), cos_t(sin_t.size()), mass(sin_t.size());
  for (int j = 0; j < r; ++j)
    for (int q = 0; q < kPoints; ++q) {
      const double u = (j + gx[std::size_t(q)]) / r, theta = ThetaGrid::theta_of_u(u);
      const std::size_t at = std::size_t(j) * kPoints + q;
      sin_t[at] = std::sin(theta);
      cos_t[at] = std::cos(theta);
      mass[at] = ndf.D(theta) * sin_t[at] * gw[std::size_t(q)] / r * kPi * u;  // d(theta) = pi u du
    }
  VisibleNormalTables tables;
  tables.resolution = r;
  tables.cdf.assign(std::size_t(n) * n, 0.0);
  tbb::parallel_for(0, n, [&](int s) {
    const double sk = std::sin(grid.theta(s)), ck = std::cos(grid.theta(s));
    double* row = tables.cdf.data() + std::size_t(s) * n;
    double sum = 0.0;
    for (int j = 0; j < r; ++j) {
      for (int q = 0; q < kPoints; ++q) {
        const std::size_t at = std::size_t(j) * kPoints + q;
        sum += mass[at] * positive_phi_integral(sk * sin_t[at], ck * cos_t[at]);
      }
      row[j + 1] = sum;
    }
    // Rounded to float, as a LUT stores them: the in-memory sampler and the baked one are then the same.
    if (sum > 0.0) {
      for (int j = 1; j <= r; ++j) row[j] = double(float(row[j] / sum));
    } else {  // no facet visible (an all-zero NDF): uniform in cos(theta), so sampling still terminates
      for (int j = 1; j <= r; ++j) row[j] = double(float(1.0 - std::cos(grid.theta(j))));
    }
    row[r] = 1.0;
  });
  return tables;
}

TabulatedMicrofacet::TabulatedMicrofacet(MicrofacetTables tables)
    : TabulatedMicrofacet(tables, VisibleNormalTables::build(tables.ndf)) {}

TabulatedMicrofacet::TabulatedMicrofacet(MicrofacetTables tables, VisibleNormalTables sampling, Stretch stretch)
    : stretch_(stretch) {
  auto shared = std::make_shared<Shared>();
  shared->tables = std::move(tables);
  shared->sampling = std::move(sampling);
  for (int j = 0; j < shared->tables.ndf.grid.size(); ++j) shared->cos_nodes.push_back(std::cos(shared->tables.ndf.grid.theta(j)));
  shared->g1.emplace(shared->tables.ndf);
  if (!shared->sampling.empty()) {
    const int r = shared->sampling.resolution;
    if (r != shared->tables.ndf.grid.resolution)
      throw std::invalid_argument("TabulatedMicrofacet: sampling tables of another resolution than the NDF's");
    for (int s = 0; s <= r; ++s) {
      for (int j = 0; j < r; ++j) {
        const double band = shared->cos_nodes[std::size_t(j)] - shared->cos_nodes[std::size_t(j) + 1];
        shared->visible_density.push_back(band > 0.0 ? shared->sampling.mass(s, j) / band : 0.0);
      }
    }
  }
  shared->parts = shared->tables.proposal_parts();
  shared_ = std::move(shared);
}

TabulatedMicrofacet TabulatedMicrofacet::stretched(const Stretch& stretch) const {
  TabulatedMicrofacet copy = *this;
  copy.stretch_ = stretch;
  return copy;
}

double TabulatedMicrofacet::D(const Vec3& h) const {
  if (h.z <= 0.0) return 0.0;
  if (stretch_.unscaled()) return shared_->tables.ndf.D(std::acos(std::min(h.z, 1.0)));
  // D_s(h) = P(slopes / s) / (s_x s_y cos^4) with P = D cos^4 of the measured normal.
  const Vec3 m = stretch_.measured_normal(stretch_.to_frame(h));
  const double r = m.z / h.z;
  return shared_->tables.ndf.D(std::acos(std::min(m.z, 1.0))) * r * r * r * r / (stretch_.x * stretch_.y);
}

double TabulatedMicrofacet::g1(const Vec3& w) const {
  if (stretch_.unscaled() || w.z <= 0.0) return (*shared_->g1)(w.z);
  return (*shared_->g1)(stretch_.direction(stretch_.to_frame(w)).z);  // Lambda_s(w) = Lambda(w')
}

Rgb TabulatedMicrofacet::fresnel(double cos_d) const { return shared_->tables.fresnel.eval(std::acos(clamp(cos_d, 0.0, 1.0))); }

std::optional<Rgb> TabulatedMicrofacet::eval(const Vec3& o, const Vec3& i) const {
  if (!above_horizon(o, i)) return Rgb(0.0);
  const Vec3 h = glm::normalize(i + o);
  const MicrofacetTables& t = shared_->tables;
  const double g2 = smith_g2_from_g1(t.smith, g1(o), g1(i));
  return t.body * (kInvPi * minnaert_factor(t.body_exponent, o.z, i.z)) + fresnel(glm::dot(i, h)) * (D(h) * g2 / (4.0 * i.z * o.z)) +
         Rgb(t.coat.eval(o, i));
}

namespace {

// Where theta sits on the grid: interval j (0..R-1) and fraction t.
struct GridPosition {
  int j;
  double t;
};

GridPosition locate(const ThetaGrid& grid, double cos_theta) {
  int j;
  double t;
  grid.locate(std::acos(clamp(cos_theta, -1.0, 1.0)), &j, &t);
  return {j, t};
}

}  // namespace

double TabulatedMicrofacet::visible_normal_pdf(const Vec3& o, const Vec3& h) const {
  if (stretch_.unscaled()) return measured_visible_normal_pdf(o, h);
  if (o.z <= 0.0 || h.z <= 0.0 || glm::dot(o, h) <= 0.0) return 0.0;
  // The measured lobe's density at the measured normal, seen from the stretched view, times the Jacobian
  // of the normals (model/stretch.h): exactly the stretched lobe's visible normals.
  const Vec3 m = stretch_.measured_normal(stretch_.to_frame(h));
  return measured_visible_normal_pdf(stretch_.direction(stretch_.to_frame(o)), m) * stretch_.normal_jacobian(h.z, m.z);
}

double TabulatedMicrofacet::measured_visible_normal_pdf(const Vec3& o, const Vec3& h) const {
  const double oh = glm::dot(o, h);
  if (o.z <= 0.0 || h.z <= 0.0 || oh <= 0.0 || shared_->sampling.empty()) return 0.0;
  const ThetaGrid& grid = shared_->tables.ndf.grid;
  const GridPosition view = locate(grid, o.z), normal = locate(grid, h.z);
  // The two view slices around o, mixed linearly in u (sample() picks one with these weights).
  const double* density = shared_->visible_density.data() + std::size_t(view.j) * grid.resolution + normal.j;
  const double per_cos = (1.0 - view.t) * density[0] + view.t * density[grid.resolution];
  if (!(per_cos > 0.0)) return 0.0;
  // Azimuth: exactly max(0, o.h) over its phi integral at this theta_h.
  const double sin_o = std::sqrt(std::max(0.0, 1.0 - o.z * o.z)), sin_h = std::sqrt(std::max(0.0, 1.0 - h.z * h.z));
  const double phi_total = positive_phi_integral(sin_o * sin_h, o.z * h.z);
  if (!(phi_total > 0.0)) return 0.0;
  return per_cos * oh / phi_total;  // d(omega) = d(cos theta) d(phi)
}

double TabulatedMicrofacet::pdf(const Vec3& o, const Vec3& i) const {
  if (i.z <= 0.0 || o.z <= 0.0 || shared_->sampling.empty()) return 0.0;
  return shared_->parts.pdf(o, i, lobe_pdf(o, i));
}

double TabulatedMicrofacet::lobe_pdf(const Vec3& o, const Vec3& i) const {
  if (i.z <= 0.0 || o.z <= 0.0) return 0.0;
  const Vec3 h = glm::normalize(o + i);
  const double oh = glm::dot(o, h);
  if (oh <= 0.0) return 0.0;
  // Reflection about h: d(omega_i) = 4 (o.h) d(omega_h).
  return visible_normal_pdf(o, h) / (4.0 * oh);
}

std::optional<TabulatedMicrofacet::Sample> TabulatedMicrofacet::sample(const Vec3& o, double u1, double u2) const {
  const auto i = sample_direction(o, u1, u2);
  if (!i) return std::nullopt;
  const double p = pdf(o, *i);
  if (!(p > 0.0)) return std::nullopt;
  return Sample{*i, *eval(*i, o) * (i->z / p), p};
}

std::optional<Vec3> TabulatedMicrofacet::sample_direction(const Vec3& o, double u1, double u2) const {
  if (o.z <= 0.0 || shared_->sampling.empty()) return std::nullopt;
  return shared_->parts.sample(o, u1, u2, [&](double a, double b) { return lobe_direction(o, a, b); });
}

std::optional<Vec3> TabulatedMicrofacet::lobe_direction(const Vec3& o, double u1, double u2) const {
  Vec3 h;
  if (stretch_.unscaled()) {
    h = measured_visible_normal(o, u1, u2);
  } else {  // the measured lobe's visible normals seen from the stretched view, stretched back
    const Vec3 m = measured_visible_normal(stretch_.direction(stretch_.to_frame(o)), u1, u2);
    h = stretch_.from_frame(stretch_.stretched_normal(m));
  }
  const Vec3 i = reflect_about(o, h);
  if (i.z <= 0.0) return std::nullopt;
  return i;
}

Vec3 TabulatedMicrofacet::measured_visible_normal(const Vec3& o, double u1, double u2) const {
  const ThetaGrid& grid = shared_->tables.ndf.grid;
  const int r = grid.resolution;
  // Pick one of the two view slices around o with the weights of the mixture, reusing u1.
  const GridPosition view = locate(grid, o.z);
  const int slice = view.j + pick_of_two(view.t, &u1);
  // The interval of theta_h: the last node whose CDF is <= u1 (zero-mass intervals are never chosen).
  const double* cdf = shared_->sampling.cdf.data() + std::size_t(slice) * (r + 1);
  double frac;
  const int j = sample_cdf(cdf, r, u1, &frac);
  const double cos_h = shared_->cos_nodes[std::size_t(j)] - frac * (shared_->cos_nodes[std::size_t(j)] - shared_->cos_nodes[std::size_t(j) + 1]);
  const double sin_h = std::sqrt(std::max(0.0, 1.0 - cos_h * cos_h));
  const double sin_o = std::sqrt(std::max(0.0, 1.0 - o.z * o.z));
  // phi relative to o's azimuth, then turned to it (no arc tangent: its cosine and sine are o.xy / |o.xy|).
  const auto [cos_phi, sin_phi] = sample_visible_azimuth(sin_o * sin_h, o.z * cos_h, u2);
  const Vec3 h(sin_h * cos_phi, sin_h * sin_phi, cos_h);
  if (!(sin_o > 0.0)) return h;
  return TurnedFrame::of_azimuth(o).from_frame(h);
}

}  // namespace facetfit
