#include "render/texture.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/memory_budget.h"
#include "io/image_file.h"

namespace facetfit {

Texture::Texture(int width, int height, std::vector<float> rgb) : width_(width), height_(height), rgb_(std::move(rgb)) {
  if (width < 1 || height < 1 || rgb_.size() != std::size_t(width) * std::size_t(height) * 3)
    throw Error("texture: " + std::to_string(rgb_.size()) + " values for " + std::to_string(width) + " x " + std::to_string(height) + " RGB pixels");
}

Texture Texture::load(const std::string& path, std::uint64_t max_bytes) {
  ImageReader in = ImageReader::open(path, "cannot open texture");
  const ImageSpec& spec = in.spec();
  const std::size_t channels = spec.channels.size();
  if (spec.width < 1 || spec.height < 1 || channels < 1 || spec.width > 65536 || spec.height > 65536 || channels > 64)
    fail(path, "texture is " + std::to_string(spec.width) + " x " + std::to_string(spec.height) + " x " +
                   std::to_string(channels) + " channels; at most 65536 x 65536, 1 to 64 channels");
  // The file's channels as floats, then the RGB copy kept.
  const std::uint64_t pixels = std::uint64_t(spec.width) * std::uint64_t(spec.height);
  check_memory(path, "a " + std::to_string(spec.width) + " x " + std::to_string(spec.height) + " texture",
               pixels * (std::uint64_t(channels) + 3u) * sizeof(float), max_bytes);
  std::vector<float> rgb = read_rgb(in, OneChannel::grey);
  return Texture(spec.width, spec.height, std::move(rgb));
}

Rgb Texture::lookup(TextureCoordinates at) const {
  // Pixel x covers [x, x + 1) / width with its value at the centre; rows count from the top, v from the bottom.
  // Only the fractional part of u and v matters: taken first, so that no coordinate overflows an int.
  const double u = at.u - std::floor(at.u), v = at.v - std::floor(at.v);
  if (!std::isfinite(u) || !std::isfinite(v)) return Rgb(rgb_[0], rgb_[1], rgb_[2]);
  const double x = u * width_ - 0.5, y = (1.0 - v) * height_ - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const double tx = x - fx, ty = y - fy;
  const auto wrap = [](double k, int n) { return ((int(k) % n) + n) % n; };
  const int x0 = wrap(fx, width_), x1 = wrap(fx + 1.0, width_), y0 = wrap(fy, height_), y1 = wrap(fy + 1.0, height_);
  const auto texel = [&](int px, int py) {
    const float* p = rgb_.data() + (std::size_t(py) * std::size_t(width_) + std::size_t(px)) * 3;
    return Rgb(p[0], p[1], p[2]);
  };
  return (1.0 - ty) * ((1.0 - tx) * texel(x0, y0) + tx * texel(x1, y0)) + ty * ((1.0 - tx) * texel(x0, y1) + tx * texel(x1, y1));
}

TextureCoordinates sphere_texture_coordinates(const Vec3& d) {
  return {0.5 - std::atan2(d.x, -d.z) * (0.5 * kInvPi), 1.0 - std::acos(clamp(d.y, -1.0, 1.0)) * kInvPi};
}

}  // namespace facetfit
