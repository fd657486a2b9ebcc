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
#include <string>

#include "color/ciede2000.h"
#include "core/rgb_space.h"
#include "core/vec.h"

namespace facetfit {

// The sRGB encoding as OCIO's ExponentWithLinearTransform computes it (gamma 2.4, offset 0.055, linear
// segment joined with a continuous slope), and its inverse. Both extend their linear segment below zero.
double srgb_encode(double linear);
double srgb_decode(double encoded);

Lab xyz_to_lab(const Vec3& xyz);  // relative to kD65White

// Display-referred sRGB code values (0..1) to CIELAB: decode, Rec.709 to XYZ, XYZ to Lab.
Lab display_to_lab(const Rgb& srgb_display);

// The OpenColorIO processor from scene-linear Rec.709 to display-referred sRGB, built once. Copies share
// the processor. Every member is const and safe to call from many threads at once (OCIO's CPU processors
// are).
class ColorConfig;

class DisplayTransform {
 public:
  // Builds the processor in code on a raw OCIO config ($OCIO and config files play no part). Throws
  // Error if OpenColorIO refuses it.
  DisplayTransform();
  // The same display for pixels of another linear space, taken to Rec.709 by `to_rec709` first.
  explicit DisplayTransform(const ColorMatrix& to_rec709);
  // A studio's picture instead: `display` and `view` of `config` (an empty view: the display's default)
  // for pixels in the config's colour space `space`, then clamped to [0, 1]. Throws Error naming what the
  // config lacks. For pictures only: Delta E is measured through the sRGB display above.
  DisplayTransform(const ColorConfig& config, const std::string& space, const std::string& display, const std::string& view);

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
