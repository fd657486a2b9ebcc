// From a renderer's scene-linear pixels to CIELAB, the way ΔE00 is measured on rendered images:
//
//   scene-linear Rec.709 --(OpenColorIO: clamp to [0, 1], sRGB encoding)--> display-referred sRGB
//   --(decode: inverse of that encoding)--> linear Rec.709 --(matrix)--> XYZ (D65) --> CIELAB (D65 white)
//
// docs/colour.md has the constants and why each step is what it is. The display transform is the one
// step a studio would swap (a tone-mapping view instead of a clamp), so it alone goes through OCIO.
#pragma once

#include <cstddef>
#include <memory>

#include "color/ciede2000.h"
#include "core/vec.h"

namespace facetfit {

// Rec.709 / sRGB primaries and the D65 white (x, y) = (0.3127, 0.3290), to XYZ with Y(white) = 1. Derived
// exactly from the chromaticities, not the 4-digit table of IEC 61966-2-1, so that the white maps to
// kD65White to the last digit and lands on L* = 100, a* = b* = 0.
constexpr double kRec709ToXyz[3][3] = {{0.4123907993, 0.3575843394, 0.1804807884},
                                       {0.2126390059, 0.7151686788, 0.0721923154},
                                       {0.0193308187, 0.1191947798, 0.9505321522}};
// XYZ of the D65 white from its chromaticity: the row sums of kRec709ToXyz.
constexpr double kD65White[3] = {0.9504559270516717, 1.0, 1.0890577507598784};

// The sRGB encoding as OCIO's ExponentWithLinearTransform computes it (gamma 2.4, offset 0.055, linear
// segment joined with a continuous slope), and its inverse. Both extend their linear segment below zero.
double srgb_encode(double linear);
double srgb_decode(double encoded);

Vec3 rec709_to_xyz(const Rgb& linear);
Lab xyz_to_lab(const Vec3& xyz);  // relative to kD65White

// Display-referred sRGB code values (0..1) to CIELAB: decode, Rec.709 to XYZ, XYZ to Lab.
Lab display_to_lab(const Rgb& srgb_display);

// The OpenColorIO processor from scene-linear Rec.709 to display-referred sRGB, built once. Copies share
// the processor. Every member is const and safe to call from many threads at once (OCIO's CPU processors
// are).
class DisplayTransform {
 public:
  // Builds the processor in code on a raw OCIO config ($OCIO and config files play no part). Throws
  // Error if OpenColorIO refuses it.
  DisplayTransform();

  // In place, `pixels` interleaved RGB triples: scene-linear in, display-referred sRGB in [0, 1] out.
  // Each channel is clamped on its own, so an out-of-gamut colour shifts hue as it does on screen.
  void to_display(float* rgb, std::size_t pixels) const;
  Rgb to_display(const Rgb& scene_linear) const;

  // display_to_lab(to_display(scene_linear)).
  Lab linear_to_lab(const Rgb& scene_linear) const;

 private:
  struct Processor;
  std::shared_ptr<const Processor> processor_;
};

}  // namespace facetfit
