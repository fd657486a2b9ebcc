// A BRDF with its frame turned about the normal: the analytic models are axis-aligned, an anisotropic
// material's axes lie anywhere.
#pragma once

#include <memory>

#include "core/brdf.h"
#include "core/frame.h"

namespace facetfit {

class RotatedBrdf final : public Brdf {
 public:
  // The base's x axis at azimuth `angle` (radians). Holds a reference: `base` outlives it.
  RotatedBrdf(const Brdf& base, double angle) : base_(base), axes_(angle) {}
  // Sharing the base's ownership (a scene's material).
  RotatedBrdf(std::shared_ptr<const Brdf> base, double angle) : owned_(std::move(base)), base_(*owned_), axes_(angle) {}
  std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const override { return base_.eval(axes_.to_frame(o), axes_.to_frame(i)); }

 private:
  std::shared_ptr<const Brdf> owned_;  // declared before base_, which may refer to it
  const Brdf& base_;
  TurnedFrame axes_;
};

}  // namespace facetfit
