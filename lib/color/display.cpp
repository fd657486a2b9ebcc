#include "color/display.h"

#include <OpenColorIO/OpenColorIO.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "color/ocio_handles.h"
#include "core/error.h"

namespace facetfit {

namespace {

// The sRGB curve as OCIO's ExponentWithLinearTransform defines it: decoded = ((x + o) / (1 + o))^g above
// the encoded breakpoint o / (g - 1), a straight line through zero below it, with value and slope
// continuous there. (IEC 61966-2-1 rounds the same joint to 0.04045 and 12.92; the two curves differ by
// less than 1e-6 in linear light.)
constexpr double kGamma = 2.4;
constexpr double kOffset = 0.055;
constexpr double kEncodedBreak = kOffset / (kGamma - 1);  // 0.0392857...
constexpr double kLinearBreak = 0.003039934639778431;     // ((kEncodedBreak + o) / (1 + o))^g
constexpr double kSlope = kEncodedBreak / kLinearBreak;   // 12.9232..., encoded per linear

// CIE 1976 L*a*b* with the exact rational constants (CIE 15:2004 note), which make f continuous.
constexpr double kEpsilon = 216.0 / 24389.0;
constexpr double kKappa = 24389.0 / 27.0;

double lab_f(double t) { return t > kEpsilon ? std::cbrt(t) : (kKappa * t + 16) / 116; }

}  // namespace

double srgb_encode(double linear) {
  return linear >= kLinearBreak ? (1 + kOffset) * std::pow(linear, 1 / kGamma) - kOffset : linear * kSlope;
}

double srgb_decode(double encoded) {
  return encoded >= kEncodedBreak ? std::pow((encoded + kOffset) / (1 + kOffset), kGamma) : encoded / kSlope;
}

Lab xyz_to_lab(const Vec3& xyz) {
  const double fx = lab_f(xyz.x / kD65White[0]), fy = lab_f(xyz.y / kD65White[1]), fz = lab_f(xyz.z / kD65White[2]);
  return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
}

Lab display_to_lab(const Rgb& s) {
  return xyz_to_lab(rec709_to_xyz(Rgb(srgb_decode(s.r), srgb_decode(s.g), srgb_decode(s.b))));
}

namespace {

// [0, 1] in every channel.
OCIO::RangeTransformRcPtr unit_clamp() {
  auto clamp = OCIO::RangeTransform::Create();
  clamp->setStyle(OCIO::RANGE_CLAMP);
  clamp->setMinInValue(0.0);
  clamp->setMinOutValue(0.0);
  clamp->setMaxInValue(1.0);
  clamp->setMaxOutValue(1.0);
  return clamp;
}

// Scene-linear Rec.709 to sRGB code values: clamp first (the encoding is monotonic and maps 0 to 0 and 1
// to 1, so clamping before it is the same as clamping the display values, and it keeps pow() away from
// negative and huge inputs), then encode.
OCIO::GroupTransformRcPtr srgb_display(const ColorMatrix& to_rec709) {
  auto group = OCIO::GroupTransform::Create();
  if (to_rec709 != ColorMatrix(1.0)) {
    auto matrix = OCIO::MatrixTransform::Create();
    double m44[16] = {0.0};
    for (int row = 0; row < 3; ++row)
      for (int column = 0; column < 3; ++column) m44[4 * row + column] = to_rec709[column][row];
    m44[15] = 1.0;
    matrix->setMatrix(m44);
    group->appendTransform(matrix);
  }
  group->appendTransform(unit_clamp());
  // OCIO's forward direction decodes (encoded to linear); inverse encodes.
  auto encode = OCIO::ExponentWithLinearTransform::Create();
  const double gamma[4] = {kGamma, kGamma, kGamma, 1.0};
  const double offset[4] = {kOffset, kOffset, kOffset, 0.0};
  encode->setGamma(gamma);
  encode->setOffset(offset);
  encode->setDirection(OCIO::TRANSFORM_DIR_INVERSE);
  group->appendTransform(encode);
  return group;
}

}  // namespace

struct DisplayTransform::Processor {
  OCIO::ConstCPUProcessorRcPtr cpu;
  // Lossless optimization: the default level (VERY_GOOD) permits fast approximations of pow().
  Processor(const OCIO::ConstConfigRcPtr& config, const OCIO::ConstTransformRcPtr& transform)
      : cpu(config->getProcessor(transform)->getOptimizedCPUProcessor(OCIO::BIT_DEPTH_F32, OCIO::BIT_DEPTH_F32,
                                                                        OCIO::OPTIMIZATION_LOSSLESS)) {}
};

DisplayTransform::DisplayTransform() : DisplayTransform(ColorMatrix(1.0)) {}

DisplayTransform::DisplayTransform(const ColorMatrix& to_rec709) {
  try {
    // A raw config: nothing read from $OCIO or disk, so every machine computes the same numbers.
    processor_ = std::make_shared<Processor>(OCIO::Config::CreateRaw(), srgb_display(to_rec709));
  } catch (const OCIO::Exception& e) {
    fail("OpenColorIO", std::string("cannot build the sRGB display transform: ") + e.what());
  }
}

DisplayTransform::DisplayTransform(const ColorConfig& config, const std::string& space, const std::string& display,
                                   const std::string& view) {
  if (!config.has_config()) fail("--display " + display, "a display needs an OpenColorIO config (--ocio-config or $OCIO)");
  const OCIO::ConstConfigRcPtr& c = config.opaque()->config;
  if (!c->getColorSpace(space.c_str())) fail(config.path(), "the config has no colour space '" + excerpt(space, 80) + "'");
  const char* chosen = view.empty() ? c->getDefaultView(display.c_str()) : view.c_str();
  bool known = false;
  for (int k = 0; k < c->getNumViews(display.c_str()); ++k) known = known || std::string(c->getView(display.c_str(), k)) == chosen;
  if (!known)
    fail(config.path(), "the config has no display '" + excerpt(display, 80) + "'" + (view.empty() ? "" : " with a view '" + excerpt(view, 80) + "'"));
  try {
    auto picture = OCIO::DisplayViewTransform::Create();
    picture->setSrc(space.c_str());
    picture->setDisplay(display.c_str());
    picture->setView(chosen);
    auto group = OCIO::GroupTransform::Create();
    group->appendTransform(picture);
    group->appendTransform(unit_clamp());  // a view may leave [0, 1] (the ACES views do)
    processor_ = std::make_shared<Processor>(c, group);
  } catch (const OCIO::Exception& e) {
    fail(config.path(), "cannot build the view '" + excerpt(chosen, 80) + "' of display '" + excerpt(display, 80) + "': " + excerpt(e.what(), 200));
  }
}

void DisplayTransform::to_display(float* rgb, std::size_t pixels) const {
  // NaN becomes black here rather than by whatever order OCIO's clamp happens to compare in: a pixel with
  // no value shows as black, and one bad pixel cannot poison a mean.
  for (std::size_t i = 0; i < 3 * pixels; ++i)
    if (std::isnan(rgb[i])) rgb[i] = 0.0f;
  // One OCIO image per 2^20 pixels keeps each width well inside PackedImageDesc's `long`.
  constexpr std::size_t kRow = std::size_t(1) << 20;
  try {
    for (std::size_t start = 0; start < pixels; start += kRow) {
      const std::size_t n = std::min(kRow, pixels - start);
      OCIO::PackedImageDesc image(rgb + 3 * start, static_cast<long>(n), 1, 3);
      processor_->cpu->apply(image);
    }
  } catch (const OCIO::Exception& e) {
    fail("OpenColorIO", std::string("display transform failed: ") + e.what());
  }
}

Rgb DisplayTransform::to_display(const Rgb& c) const {
  float v[3] = {float(c.r), float(c.g), float(c.b)};
  to_display(v, 1);
  return {v[0], v[1], v[2]};
}

Lab DisplayTransform::linear_to_lab(const Rgb& scene_linear) const { return display_to_lab(to_display(scene_linear)); }

}  // namespace facetfit
