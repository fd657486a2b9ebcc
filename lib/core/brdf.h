// The one interface every material source offers: RGB reflectance for a pair of directions.
#pragma once

#include <optional>

#include "core/vec.h"

namespace facetfit {

// A light direction drawn for a view direction: what every sampler of a lobe or a material returns.
struct BrdfSample {
  Vec3 i;
  Rgb weight;  // f(o, i) cos(theta_i) / pdf
  double pdf;  // per steradian of i
};

// A BRDF f(o, i) in 1/sr. Conventions (docs/conventions.md): both directions are unit vectors in the
// local frame with the surface normal along +z, pointing away from the surface; o toward the viewer,
// i toward the light, in that order in every eval, pdf and sample (as pbrt's f(wo, wi)). Implementations are reciprocal where the physics is, and thread-safe for eval.
class Brdf {
 public:
  virtual ~Brdf() = default;

  // Reflectance, or nullopt where the source has no measurement for this pair (a measured table's
  // missing bin). Analytic models always answer; below the horizon they answer zero.
  virtual std::optional<Rgb> eval(const Vec3& o, const Vec3& i) const = 0;
};

// A measurement that is not one reciprocal table but two estimates of each direction pair, each read
// from the data taken with one of the two directions held fixed (an RGL file's slices). A renderer
// reads the estimate of the viewer's direction (Mitsuba's `measured`); the fits compare a reciprocal
// model with both, each where it was measured.
class OneSidedMeasurement {
 public:
  virtual ~OneSidedMeasurement() = default;

  // T(p, q) = f(p, q) cos(theta_q) as read from the data of direction p (p, q unit, above the horizon),
  // RGB; nullopt where p lies past the elevations the data were measured at.
  virtual std::optional<Rgb> one_sided(const Vec3& p, const Vec3& q) const = 0;
};

// One direction pair a source was measured at, with its value, as the source holds it (a UTIA file's
// nodes): the fits compare a model there rather than with a table resampled between the nodes.
struct MeasuredSample {
  Vec3 o, i;
  Rgb f;           // 1/sr
  double measure;  // d(omega_o) d(omega_i) of the cell the sample stands for
};

}  // namespace facetfit
