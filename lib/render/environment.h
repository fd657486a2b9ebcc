// A distant environment light: a lat-long radiance image, importance-sampled.
//
// World frame: +y is up. Direction d has theta = acos(d.y) from the zenith and phi = atan2(d.x, -d.z);
// pixel (x, y) covers u = (phi + pi) / (2 pi) in [x/W, (x+1)/W) and v = theta / pi in [y/H, (y+1)/H).
// Radiance is constant over a pixel, so the sampling density (proportional to luminance x sin(theta)
// per pixel) and radiance() agree exactly, as multiple importance sampling needs.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/piecewise_constant.h"
#include "core/vec.h"

namespace facetfit {

class Environment {
 public:
  static Environment constant(const Rgb& radiance);
  // `rgb` holds width x height interleaved linear Rec.709 values, row 0 at the zenith.
  static Environment from_pixels(int width, int height, std::vector<float> rgb);
  // Any image facetfit reads (io/image_file.h: EXR, HDR ...); throws Error naming the file.
  // Refuses, before reading its pixels, a map whose pixels and sampling tables would take more than
  // `max_bytes`.
  static Environment load(const std::string& path, std::uint64_t max_bytes);
  // Bytes a loaded map of width x height x channels takes at its peak (file pixels, colour, sampling tables).
  static std::uint64_t bytes_to_load(int width, int height, int channels);
  // The built-in sky: a zenith-to-horizon gradient, a darker ground, and a small bright sun. Needs no file.
  static Environment sky(int width = 512);

  Rgb radiance(const Vec3& d) const;
  struct Sample {
    Vec3 d;
    Rgb radiance;
    double pdf;  // per steradian
  };
  // Radiance and pdf of a direction with one pixel lookup (the d of the result is d). Inline for the
  // constant environment, which every BRDF sample of a sphere under it asks.
  Sample lookup(const Vec3& d) const {
    if (is_constant()) return {d, constant_, 1.0 / (4.0 * kPi)};
    return lookup_map(d);
  }
  Sample sample(double u1, double u2) const;
  double pdf(const Vec3& d) const;
  bool is_constant() const { return width_ == 0; }
  const std::vector<float>& pixels() const { return rgb_; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  void build_distribution();
  int pixel_of(const Vec3& d, int* x, int* y) const;
  Sample at_pixel(const Vec3& d, int pixel) const;
  Sample lookup_map(const Vec3& d) const;

  int width_ = 0, height_ = 0;  // 0: constant
  Rgb constant_{0.0};
  std::vector<float> rgb_;
  PiecewiseConstant2D distribution_;  // over [0,1]^2 of the pixels: luminance x sin(theta)
};

// Direction of the built-in sky's sun (toward the sun).
Vec3 builtin_sun_direction();

}  // namespace facetfit
