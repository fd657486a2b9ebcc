// A BRDF with its frame turned about the normal: the analytic models are axis-aligned, an anisotropic
// material's axes lie anywhere.
#pragma once

#include <cmath>
#include <memory>

#include "core/brdf.h"

namespace facetfit {

class RotatedBrdf final : public Brdf {
 public:
  // The base's x axis at azimuth `angle` (radians). Holds a reference: `base` outlives it.
  RotatedBrdf(const Brdf& base, double angle) : base_(base), c_(std::cos(angle)), s_(std::sin(angle)) {}
  // Sharing the base's ownership (a scene's material).
  RotatedBrdf(std::shared_ptr<const Brdf> base, double angle) : owned_(std::move(base)), base_(*owned_), c_(std::cos(angle)), s_(std::sin(angle)) {}
  std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const override { return base_.eval(turn(o), turn(i)); }

 private:
  Vec3 turn(const Vec3& v) const { return {c_ * v.x + s_ * v.y, -s_ * v.x + c_ * v.y, v.z}; }  // by -angle
  std::shared_ptr<const Brdf> owned_;  // declared before base_, which may refer to it
  const Brdf& base_;
  double c_, s_;
};

}  // namespace facetfit
