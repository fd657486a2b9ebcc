// Linear colour spaces as facetfit carries them: a name and the 3x3 matrix from linear Rec.709.
//
// facetfit measures and fits in linear RGB with Rec.709 primaries and the D65 white (kRec709Space): the
// RGB of MERL, RGL and UTIA files. A studio renders in another linear space (ACEScg), named by its
// OpenColorIO config (color/ocio_config.h reads the matrices off it). Between two linear spaces a colour
// converts by one matrix, rgb_to = M rgb_from; a LUT and a render record the space their colours are in.
#pragma once

#include <array>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>

#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "core/vec.h"

namespace facetfit {

using ColorMatrix = glm::dmat3;  // GLM's: column k is the image of the k-th unit vector

// facetfit's own space, known without a config; every ACES and OCIO studio config aliases its linear
// Rec.709 space so.
inline constexpr const char* kRec709Space = "lin_rec709";

// Rec.709 / sRGB primaries and the D65 white (x, y) = (0.3127, 0.3290), to XYZ with Y(white) = 1. Derived
// exactly from the chromaticities, not the 4-digit table of IEC 61966-2-1, so that the white maps to
// kD65White to the last digit and lands on L* = 100, a* = b* = 0.
constexpr double kRec709ToXyz[3][3] = {{0.4123907993, 0.3575843394, 0.1804807884},
                                       {0.2126390059, 0.7151686788, 0.0721923154},
                                       {0.0193308187, 0.1191947798, 0.9505321522}};
// XYZ of the D65 white from its chromaticity: the row sums of kRec709ToXyz.
constexpr double kD65White[3] = {0.9504559270516717, 1.0, 1.0890577507598784};

inline Vec3 rec709_to_xyz(const Rgb& c) {
  const auto& m = kRec709ToXyz;
  return {m[0][0] * c.r + m[0][1] * c.g + m[0][2] * c.b, m[1][0] * c.r + m[1][1] * c.g + m[1][2] * c.b,
          m[2][0] * c.r + m[2][1] * c.g + m[2][2] * c.b};
}

// The (x, y) chromaticities of red, green, blue and white of the space whose matrix from Rec.709 is
// `from_rec709`, in the order of OpenEXR's `chromaticities` attribute: each primary and the white taken
// back to Rec.709, then to XYZ.
inline std::array<float, 8> chromaticities(const ColorMatrix& from_rec709) {
  const ColorMatrix to_rec709 = glm::inverse(from_rec709);
  std::array<float, 8> xy{};
  for (int k = 0; k < 4; ++k) {
    const Vec3 xyz = rec709_to_xyz(k < 3 ? to_rec709[k] : to_rec709 * Rgb(1.0));
    const double sum = xyz.x + xyz.y + xyz.z;
    xy[2 * k] = float(xyz.x / sum);
    xy[2 * k + 1] = float(xyz.y / sum);
  }
  return xy;
}

// Pixels of `stride` floats, RGB first, converted in place: rgb = m rgb.
inline void convert_pixels(float* px, std::size_t pixels, int stride, const ColorMatrix& m) {
  for (std::size_t p = 0; p < pixels; ++p, px += stride) {
    const Rgb c = m * Rgb(px[0], px[1], px[2]);
    px[0] = float(c.r), px[1] = float(c.g), px[2] = float(c.b);
  }
}

// A matrix as text, nine numbers row by row (facetfit:colorspace_matrix of a LUT or a render), and back:
// nullopt unless nine numbers within +-100 with a determinant above 1e-6 (a conversion between two RGB
// spaces of real primaries has entries of a few units: ACEScg's from Rec.709 are within 0.02-0.9).
inline std::string matrix_text(const ColorMatrix& m) {
  std::ostringstream out;
  out.precision(17);
  for (int row = 0; row < 3; ++row)
    for (int column = 0; column < 3; ++column) out << (row + column > 0 ? " " : "") << m[column][row];
  return out.str();
}
inline std::optional<ColorMatrix> parse_matrix(const std::string& text) {
  std::istringstream in(text);
  ColorMatrix m;
  for (int row = 0; row < 3; ++row)
    for (int column = 0; column < 3; ++column)
      if (!(in >> m[column][row]) || !(std::abs(m[column][row]) <= 100.0)) return std::nullopt;
  std::string rest;
  if (in >> rest || !(std::abs(glm::determinant(m)) > 1e-6)) return std::nullopt;
  return m;
}

}  // namespace facetfit
