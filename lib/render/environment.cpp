#include "render/environment.h"


#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/memory_budget.h"
#include "io/image_file.h"

namespace facetfit {

namespace {

Vec3 direction_of(double u, double v) {
  const double phi = u * 2.0 * kPi - kPi, theta = v * kPi;
  const double s = std::sin(theta);
  return {s * std::sin(phi), std::cos(theta), -s * std::cos(phi)};
}

}  // namespace

Vec3 builtin_sun_direction() { return glm::normalize(Vec3(0.45, 0.55, 0.70)); }

Environment Environment::constant(const Rgb& radiance) {
  Environment env;
  env.constant_ = radiance;
  return env;
}

Environment Environment::from_pixels(int width, int height, std::vector<float> rgb) {
  if (width < 1 || height < 1 || rgb.size() != std::size_t(width) * height * 3) throw Error("environment: bad image size");
  Environment env;
  env.width_ = width;
  env.height_ = height;
  env.rgb_ = std::move(rgb);
  for (float& v : env.rgb_)
    if (!std::isfinite(v) || v < 0.0f) v = 0.0f;
  env.build_distribution();
  return env;
}

std::uint64_t Environment::bytes_to_load(int width, int height, int channels) {
  // Per pixel: the file's channels as float, two RGB copies (the map's, and the scaled one a scene may
  // make), and PiecewiseConstant2D's weights, running sums and densities (doubles).
  return std::uint64_t(width) * std::uint64_t(height) * (4u * std::uint64_t(channels) + 24u + 32u);
}

Environment Environment::load(const std::string& path, std::uint64_t max_bytes) {
  ImageReader in = ImageReader::open(path, "cannot open environment map");
  const ImageSpec& spec = in.spec();
  const int channels = int(spec.channels.size());
  if (spec.width < 2 || spec.height < 1 || spec.width > 65536 || spec.height > 32768 || channels < 1 || channels > 64)
    fail(path, "environment map is " + std::to_string(spec.width) + " x " + std::to_string(spec.height) + " x " +
                   std::to_string(channels) + " channels; at most 65536 x 32768, at least 2 x 1, 1 to 64 channels");
  check_memory(path, "a " + std::to_string(spec.width) + " x " + std::to_string(spec.height) + " environment map",
               bytes_to_load(spec.width, spec.height, channels), max_bytes);
  std::vector<float> rgb = read_rgb(in, OneChannel::grey);
  return from_pixels(spec.width, spec.height, std::move(rgb));
}

Environment Environment::sky(int width) {
  const int height = width / 2;
  std::vector<float> rgb(std::size_t(width) * height * 3);
  const Vec3 sun = builtin_sun_direction();
  const double sun_cos = std::cos(2.5 * kPi / 180.0);  // a 5-degree disc: small, bright, still resolvable
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const Vec3 d = direction_of((x + 0.5) / width, (y + 0.5) / height);
      Rgb c;
      if (d.y >= 0.0) {
        const double t = std::pow(1.0 - d.y, 3.0);  // whiter toward the horizon
        c = glm::mix(Rgb(0.25, 0.45, 0.95), Rgb(0.9, 0.92, 1.0), t);
      } else {
        c = Rgb(0.18, 0.16, 0.14) * (0.6 + 0.4 * (1.0 + d.y));
      }
      if (glm::dot(d, sun) > sun_cos) c += Rgb(40.0, 36.0, 30.0);
      for (int k = 0; k < 3; ++k) rgb[(std::size_t(y) * width + x) * 3 + k] = float(c[k]);
    }
  return from_pixels(width, height, std::move(rgb));
}

void Environment::build_distribution() {
  const int w = width_, h = height_;
  std::vector<double> weight(std::size_t(w) * h);
  for (int y = 0; y < h; ++y) {
    const double s = std::sin((y + 0.5) / h * kPi);
    for (int x = 0; x < w; ++x) {
      const float* p = rgb_.data() + (std::size_t(y) * w + x) * 3;
      // A floor keeps every direction samplable, so light sampling alone is unbiased too.
      weight[std::size_t(y) * w + x] = (luminance(Rgb(p[0], p[1], p[2])) + 1e-4) * s;
    }
  }
  distribution_ = PiecewiseConstant2D(weight, w, h);
}

int Environment::pixel_of(const Vec3& d, int* x, int* y) const {
  const double theta = std::acos(clamp(d.y, -1.0, 1.0)), phi = std::atan2(d.x, -d.z);
  *x = std::clamp(int((phi + kPi) / (2.0 * kPi) * width_), 0, width_ - 1);
  *y = std::clamp(int(theta / kPi * height_), 0, height_ - 1);
  return *y * width_ + *x;
}

Rgb Environment::radiance(const Vec3& d) const { return lookup(d).radiance; }

Environment::Sample Environment::at_pixel(const Vec3& d, int pixel) const {
  const float* p = rgb_.data() + std::size_t(pixel) * 3;
  const double s = std::sqrt(std::max(0.0, 1.0 - d.y * d.y));
  // Density over [0,1]^2 to solid angle: d(omega) = 2 pi^2 sin(theta) du dv.
  const double pdf = s > 0.0 ? distribution_.pdf(pixel % width_, pixel / width_) / (2.0 * kPi * kPi * s) : 0.0;
  return {d, Rgb(p[0], p[1], p[2]), pdf};
}

Environment::Sample Environment::lookup_map(const Vec3& d) const {
  int x, y;
  return at_pixel(d, pixel_of(d, &x, &y));
}

Environment::Sample Environment::sample(double u1, double u2) const {
  if (is_constant()) {  // uniform sphere
    const double z = 1.0 - 2.0 * u1, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 2.0 * kPi * u2;
    return {Vec3(r * std::cos(phi), z, r * std::sin(phi)), constant_, 1.0 / (4.0 * kPi)};
  }
  const PiecewiseConstant2D::Sample p = distribution_.sample(u1, u2);
  return at_pixel(direction_of(p.u, p.v), p.y * width_ + p.x);  // the pixel drawn: no second lookup
}

double Environment::pdf(const Vec3& d) const { return lookup(d).pdf; }

}  // namespace facetfit
