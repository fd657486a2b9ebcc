#include "model/closures.h"

#include <algorithm>
#include <cmath>

#include "model/fresnel.h"
#include "model/ggx_visible.h"
#include "model/smith.h"
#include "model/tabulated_ndf.h"
#include "model/visible_slopes.h"

namespace facetfit {

double alpha_across_view(double alpha, double k, double cos_o) {
  // cos_o at least 1e-3: a view at the horizon sees no lobe, and the power stays finite.
  return std::min(alpha * std::pow(std::max(cos_o, 1e-3), -k), std::max(alpha, 1.0));
}

Ndf ClosureLobe::ndf(double cos_o) const {
  if (!view_aligned()) return {type, alpha_x, alpha_y};
  return {type, alpha_x, alpha_across_view(alpha_y, view_exponent, cos_o)};
}

Rgb ClosureLobe::fresnel_at(double cos_d) const {
  const double mu = clamp(cos_d, 0.0, 1.0);
  if (fresnel == Fresnel::f82_tint) return F82Tint(f0, f82).eval(mu);
  return fresnel_formulas::generalized_schlick(f0, f90, std::pow(1.0 - mu, exponent));
}

namespace {

// The least-squares f90 of f0 + (f90 - f0) (1 - mu)^e against `lobe`'s curve at the nodes, clamped to
// [0, 1], and the squared error summed over channels and nodes.
std::pair<Rgb, double> schlick_f90(const ClosureLobe& lobe, double e, const std::vector<double>& mus) {
  Rgb cross(0.0);
  double square = 0.0;
  for (double mu : mus) {
    const double p = std::pow(1.0 - mu, e);
    cross += p * (lobe.fresnel_at(mu) - lobe.f0);
    square += p * p;
  }
  const Rgb f90 = glm::clamp(lobe.f0 + cross / square, Rgb(0.0), Rgb(1.0));
  double error = 0.0;
  for (double mu : mus) {
    const Rgb r = lobe.fresnel_at(mu) - fresnel_formulas::generalized_schlick(lobe.f0, f90, std::pow(1.0 - mu, e));
    error += glm::dot(r, r);
  }
  return {f90, error};
}

}  // namespace

ClosureLobe without_f82(const ClosureLobe& lobe) {
  if (lobe.fresnel != ClosureLobe::Fresnel::f82_tint) return lobe;
  std::vector<double> mus;
  for (int j = 0; j < 256; ++j) mus.push_back((j + 0.5) / 256.0);
  // A scan of 31 exponents, log-spaced over [1, 16], then golden-section search between the best one's
  // neighbours.
  const auto error = [&](double e) { return schlick_f90(lobe, e, mus).second; };
  const auto exponent = [](int k) { return std::pow(16.0, k / 30.0); };
  int best = 0;
  for (int k = 1; k <= 30; ++k)
    if (error(exponent(k)) < error(exponent(best))) best = k;
  double lo = exponent(std::max(best - 1, 0)), hi = exponent(std::min(best + 1, 30));
  const double golden = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int step = 0; step < 40; ++step) {
    const double a = hi - golden * (hi - lo), b = lo + golden * (hi - lo);
    if (error(a) < error(b))
      hi = b;
    else
      lo = a;
  }
  ClosureLobe out = lobe;
  out.fresnel = ClosureLobe::Fresnel::schlick;
  out.exponent = 0.5 * (lo + hi);
  out.f90 = schlick_f90(lobe, out.exponent, mus).first;
  return out;
}

ClosureBrdf::ClosureBrdf(Closures closures) : closures_(std::move(closures)) {
  for (const ClosureLobe& l : closures_.lobes) axes_.emplace_back(l.angle);
}

std::optional<Rgb> ClosureBrdf::eval(const Vec3& o, const Vec3& i) const {
  if (!above_horizon(o, i)) return Rgb(0.0);
  const Vec3 h = glm::normalize(i + o);
  const double cos_d = clamp(glm::dot(i, h), 0.0, 1.0), projected = 4.0 * i.z * o.z;
  Rgb f = closures_.body * kInvPi + Rgb(closures_.coat.eval(o, i));
  for (std::size_t k = 0; k < axes_.size(); ++k) {
    const ClosureLobe& l = closures_.lobes[k];
    const TurnedFrame axes = l.view_aligned() ? TurnedFrame::of_azimuth(o) : axes_[k];
    const Ndf ndf = l.ndf(o.z);
    const Vec3 lo = axes.to_frame(o), li = axes.to_frame(i), lh = axes.to_frame(h);
    const double g2 = smith_g2(Smith::correlated, ndf.lambda(lo), ndf.lambda(li));
    f += l.weight * l.fresnel_at(cos_d) * (ndf.D(lh) * g2 / projected);
  }
  return f;
}

Closures Closures::stretched(double x, double y, double rotation) const {
  Closures c = *this;
  for (ClosureLobe& l : c.lobes) {
    if (l.view_aligned()) {
      const double mean = std::sqrt(x * y);
      l.alpha_x *= mean, l.alpha_y *= mean;
      continue;
    }
    l.alpha_x *= x, l.alpha_y *= y, l.angle += rotation;
  }
  return c;
}

ClosureProposal::ClosureProposal(const Closures& closures) : coat_(closures.coat) {
  double total = 0.0;
  for (const ClosureLobe& l : closures.lobes) {
    Lobe lobe{std::max(l.weight * luminance(l.fresnel_at(0.5)), 0.05), l, TurnedFrame(l.angle), nullptr};
    if (l.type != NdfType::ggx)  // an older LUT's Beckmann lobe, never view-aligned
      lobe.beckmann = std::make_shared<VisibleSlopeProposal>(tabulate_ndf(Ndf::isotropic(l.type, std::sqrt(l.alpha_x * l.alpha_y))),
                                                             ProposalParts{});
    total += lobe.probability;
    lobes_.push_back(std::move(lobe));
  }
  body_ = std::max(luminance(closures.body), 0.0);
  coat_probability_ = coat_.present() ? std::max(coat_.f0, 0.1) : 0.0;
  total += body_ + coat_probability_;
  if (!(total > 0.0 && std::isfinite(total))) return;
  for (Lobe& lobe : lobes_) lobe.probability /= total;
  body_ /= total;
  coat_probability_ /= total;
}

std::optional<Vec3> ClosureProposal::sample_direction(const Vec3& o, double u1, double u2) const {
  if (o.z <= 0.0) return std::nullopt;
  for (const Lobe& lobe : lobes_) {
    const double p = lobe.probability;
    if (u1 >= p) {
      u1 -= p;
      continue;
    }
    if (lobe.beckmann) return lobe.beckmann->sample_direction(o, u1 / p, u2);
    const TurnedFrame axes = lobe.lobe.view_aligned() ? TurnedFrame::of_azimuth(o) : lobe.axes;
    const auto i = ggx_visible_direction(axes.to_frame(o), lobe.lobe.ndf(o.z), u1 / p, u2);
    return i ? std::optional<Vec3>(axes.from_frame(*i)) : std::nullopt;
  }
  if (u1 < body_) return cosine_direction(u1 / body_, u2);
  if (coat_probability_ <= 0.0) return std::nullopt;
  return coat_.sample_direction(o, clamp((u1 - body_) / coat_probability_, 0.0, 1.0 - 1e-16), u2);
}

double ClosureProposal::pdf(const Vec3& o, const Vec3& i) const {
  if (i.z <= 0.0 || o.z <= 0.0) return 0.0;
  double density = body_ * i.z * kInvPi + coat_probability_ * coat_.pdf(o, i);
  for (const Lobe& lobe : lobes_) {
    if (lobe.beckmann) {
      density += lobe.probability * lobe.beckmann->pdf(o, i);
      continue;
    }
    const TurnedFrame axes = lobe.lobe.view_aligned() ? TurnedFrame::of_azimuth(o) : lobe.axes;
    density += lobe.probability * ggx_visible_pdf(axes.to_frame(o), axes.to_frame(i), lobe.lobe.ndf(o.z));
  }
  return density;
}

}  // namespace facetfit
