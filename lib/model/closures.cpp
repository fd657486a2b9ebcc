#include "model/closures.h"

#include <algorithm>
#include <cmath>

#include "model/smith.h"
#include "model/tabulated_ndf.h"
#include "model/visible_slopes.h"

namespace facetfit {

Rgb ClosureLobe::fresnel_at(double cos_d) const {
  const double mu = clamp(cos_d, 0.0, 1.0);
  if (fresnel == Fresnel::f82_tint) return F82Tint(f0, f82).eval(mu);
  return f0 + (f90 - f0) * std::pow(1.0 - mu, exponent);
}

ClosureBrdf::ClosureBrdf(Closures closures) : closures_(std::move(closures)) {
  for (const ClosureLobe& l : closures_.lobes) lobes_.push_back({l.ndf(), TurnedFrame(l.angle)});
}

std::optional<Rgb> ClosureBrdf::eval(const Vec3& o, const Vec3& i) const {
  if (!above_horizon(o, i)) return Rgb(0.0);
  const Vec3 h = glm::normalize(i + o);
  const double cos_d = clamp(glm::dot(i, h), 0.0, 1.0), projected = 4.0 * i.z * o.z;
  Rgb f = closures_.body * kInvPi + Rgb(closures_.coat.eval(o, i));
  for (std::size_t k = 0; k < lobes_.size(); ++k) {
    const Lobe& lobe = lobes_[k];
    const Vec3 lo = lobe.axes.to_frame(o), li = lobe.axes.to_frame(i), lh = lobe.axes.to_frame(h);
    const double g2 = smith_g2(Smith::correlated, lobe.ndf.lambda(lo), lobe.ndf.lambda(li));
    const ClosureLobe& l = closures_.lobes[k];
    f += l.weight * l.fresnel_at(cos_d) * (lobe.ndf.D(lh) * g2 / projected);
  }
  return f;
}

Closures Closures::stretched(double x, double y, double rotation) const {
  Closures c = *this;
  for (ClosureLobe& l : c.lobes) l.alpha_x *= x, l.alpha_y *= y, l.angle += rotation;
  return c;
}

ClosureProposal::ClosureProposal(const Closures& closures) : coat_(closures.coat) {
  double total = 0.0;
  for (const ClosureLobe& l : closures.lobes) {
    const Ndf ndf = Ndf::isotropic(l.type, std::sqrt(l.alpha_x * l.alpha_y));
    std::shared_ptr<const Proposal> proposal;
    if (l.type == NdfType::ggx)
      proposal = std::make_shared<GgxProposal>(ndf.alpha_x, Rgb(1.0), Rgb(0.0), Coat{});
    else
      proposal = std::make_shared<VisibleSlopeProposal>(tabulate_ndf(ndf), ProposalParts{});
    const double p = std::max(l.weight * luminance(l.fresnel_at(0.5)), 0.05);
    lobes_.emplace_back(p, std::move(proposal));
    total += p;
  }
  body_ = std::max(luminance(closures.body), 0.0);
  coat_probability_ = coat_.present() ? std::max(coat_.f0, 0.1) : 0.0;
  total += body_ + coat_probability_;
  if (!(total > 0.0 && std::isfinite(total))) return;
  for (auto& lobe : lobes_) lobe.first /= total;
  body_ /= total;
  coat_probability_ /= total;
}

std::optional<Vec3> ClosureProposal::sample_direction(const Vec3& o, double u1, double u2) const {
  if (o.z <= 0.0) return std::nullopt;
  for (const auto& [p, proposal] : lobes_) {
    if (u1 < p) return proposal->sample_direction(o, u1 / p, u2);
    u1 -= p;
  }
  if (u1 < body_) return cosine_direction(u1 / body_, u2);
  if (coat_probability_ <= 0.0) return std::nullopt;
  return coat_.sample_direction(o, clamp((u1 - body_) / coat_probability_, 0.0, 1.0 - 1e-16), u2);
}

double ClosureProposal::pdf(const Vec3& o, const Vec3& i) const {
  if (i.z <= 0.0 || o.z <= 0.0) return 0.0;
  double density = body_ * i.z * kInvPi + coat_probability_ * coat_.pdf(o, i);
  for (const auto& [p, proposal] : lobes_) density += p * proposal->pdf(o, i);
  return density;
}

}  // namespace facetfit
