// What proposes light directions i for a view direction o: the renderer's importance sampling.
//
// A fitted material is a lobe, a Lambertian body and an optional coat; its proposal picks one part with
// probabilities set by their albedos (luminance of F(0) for the lobe and the coat's f0, both at least 0.1
// so that a dark lobe is still found, the body's luminance), then draws from it: the lobe's visible
// normals, the cosine, the coat's GGX visible normals. pdf() is the mixture's. The tabulated model
// (model/tabulated.h) samples its lobe from tables; a GGX lobe is sampled in closed form (GgxProposal).
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/vec.h"
#include "model/coat.h"
#include "model/ggx_visible.h"
#include "model/scalar_ops.h"

namespace facetfit {

class Proposal {
 public:
  virtual ~Proposal() = default;
  virtual bool can_sample() const { return true; }
  // A direction from two uniform numbers in [0, 1); nullopt when it falls below the horizon.
  virtual std::optional<Vec3> sample_direction(const Vec3& o, double u1, double u2) const = 0;
  // Density of sample_direction() per steradian of i.
  virtual double pdf(const Vec3& o, const Vec3& i) const = 0;
};

namespace warps {
#include "model/warps-inl.h"
}  // namespace warps

// A direction of density cos(theta) / pi from two uniform numbers (warps::cosine_hemisphere); nullopt on
// the horizon.
inline std::optional<Vec3> cosine_direction(double u1, double u2) {
  const double phi = 2.0 * kPi * u2;
  Vec3 i;
  warps::cosine_hemisphere(ScalarOps{}, u1, std::cos(phi), std::sin(phi), i.x, i.y, i.z);
  if (i.z <= 0.0) return std::nullopt;
  return i;
}

// The three parts of a fitted material and their probabilities (lobe + body + coat = 1).
struct ProposalParts {
  double lobe = 1.0, body = 0.0;
  Coat coat;

  ProposalParts() = default;
  ProposalParts(const Rgb& f0, const Rgb& body_albedo, const Coat& c) : coat(c) {
    const double l = std::max(luminance(f0), 0.1), b = std::max(luminance(body_albedo), 0.0);
    const double k = coat.present() ? std::max(coat.f0, 0.1) : 0.0;
    if (std::isfinite(l + b + k)) lobe = l / (l + b + k), body = b / (l + b + k);
  }
  double coat_weight() const { return 1.0 - lobe - body; }

  // u1 picks the part (its first `lobe` selects the lobe, the next `body` the body) and is rescaled to
  // [0, 1) within it; lobe_direction(u1, u2) draws from the lobe.
  template <class LobeDirection>
  std::optional<Vec3> sample(const Vec3& o, double u1, double u2, const LobeDirection& lobe_direction) const {
    if (u1 < lobe) return lobe_direction(u1 / lobe, u2);
    u1 -= lobe;
    if (u1 < body) return cosine_direction(u1 / body, u2);
    return coat.sample_direction(o, clamp((u1 - body) / coat_weight(), 0.0, 1.0 - 1e-16), u2);
  }
  // The mixture's density, given the lobe's.
  double pdf(const Vec3& o, const Vec3& i, double lobe_pdf) const {
    double p = lobe * lobe_pdf + body * i.z * kInvPi;
    if (coat.present()) p += coat_weight() * coat.pdf(o, i);
    return p;
  }
};

// The proposal of a GGX material: its visible normals in closed form, with the body and the coat.
class GgxProposal final : public Proposal {
 public:
  GgxProposal(double alpha, const Rgb& f0, const Rgb& body, const Coat& coat) : alpha_(alpha), parts_(f0, body, coat) {}
  std::optional<Vec3> sample_direction(const Vec3& o, double u1, double u2) const override {
    if (o.z <= 0.0) return std::nullopt;
    return parts_.sample(o, u1, u2, [&](double a, double b) { return ggx_visible_direction(o, alpha_, a, b); });
  }
  double pdf(const Vec3& o, const Vec3& i) const override {
    if (i.z <= 0.0 || o.z <= 0.0) return 0.0;
    return parts_.pdf(o, i, ggx_visible_pdf(o, i, alpha_));
  }
  // pdf() from what a caller evaluating a GGX lobe of the same alpha has already computed: the half
  // vector h, D(h) and G1(o).
  double pdf_with(const Vec3& o, const Vec3& i, const Vec3& h, double d, double g1_o) const {
    if (i.z <= 0.0 || o.z <= 0.0) return 0.0;
    return parts_.pdf(o, i, ggx_visible_pdf_of(o, h, d, g1_o));
  }
  double alpha() const { return alpha_; }
  const ProposalParts& parts() const { return parts_; }

 private:
  double alpha_;
  ProposalParts parts_;
};

}  // namespace facetfit
