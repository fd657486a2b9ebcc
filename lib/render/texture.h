// An image that drives a material parameter over a surface (the roughness texture of Dupuy et al. 2015,
// section 6: a stretch per shading point), read as Blender's Image Texture node reads it with linear
// interpolation and repeat extension, so that a Cycles render of the same texture agrees:
// (u, v) in [0, 1)^2 with v = 0 at the image's bottom row, bilinear between pixel centres, both axes
// periodic.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/vec.h"

namespace facetfit {

struct TextureCoordinates {
  double u = 0.0, v = 0.0;
};

class Texture {
 public:
  // Any image facetfit reads (io/image_file.h: EXR, and through OpenImageIO PNG, TIFF ...); R, G, B by name (a grey image repeats its channel). Throws Error naming
  // the file for an unreadable image, one over `max_bytes`, or a non-finite pixel.
  static Texture load(const std::string& path, std::uint64_t max_bytes);
  // `rgb`: width x height interleaved values, row 0 at the top (as image files store them).
  Texture(int width, int height, std::vector<float> rgb);

  Rgb lookup(TextureCoordinates at) const;
  int width() const { return width_; }
  int height() const { return height_; }
  std::uint64_t bytes() const { return rgb_.size() * sizeof(float); }

 private:
  int width_ = 0, height_ = 0;
  std::vector<float> rgb_;
};

// Texture coordinates of a point on a sphere (its direction d from the centre, unit, world frame):
// Blender's sphere projection of the same point in Blender's frame (z up: facetfit's (x, -z, y)),
//   u = 1/2 - atan2(d.x, -d.z) / 2 pi,   v = 1 - acos(d.y) / pi,
// so v runs from the bottom pole (0) to the top (1) and u turns once around the vertical axis.
TextureCoordinates sphere_texture_coordinates(const Vec3& d);

}  // namespace facetfit
