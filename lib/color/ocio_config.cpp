#include "color/ocio_config.h"

#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <filesystem>

#include <glm/matrix.hpp>

#include "color/ocio_handles.h"
#include "core/error.h"

namespace facetfit {

namespace {

namespace fs = std::filesystem;

// What a config's transforms may read: regular files up to this size (a 65^3 cube LUT as text is ~10 MB).
constexpr std::uintmax_t kMaxTransformFileBytes = 256ull << 20;

// Every file a transform (its groups' members included) reads, resolved as OCIO resolves it, is a regular
// file within kMaxTransformFileBytes: OCIO reads a FileTransform's src whole when it builds a processor, so
// a device (/dev/zero: gigabytes), a FIFO (a hang) or a huge file is refused before that, by name.
void check_transform_files(const std::string& path, const OCIO::Config& config, const OCIO::ConstTransformRcPtr& t) {
  if (!t) return;
  if (const auto group = OCIO::DynamicPtrCast<const OCIO::GroupTransform>(t)) {
    for (int k = 0; k < group->getNumTransforms(); ++k) check_transform_files(path, config, group->getTransform(k));
    return;
  }
  const auto file = OCIO::DynamicPtrCast<const OCIO::FileTransform>(t);
  if (!file || !file->getSrc()) return;
  std::string resolved;
  try {
    resolved = config.getCurrentContext()->resolveFileLocation(file->getSrc());
  } catch (const OCIO::Exception&) {
    return;  // not found: OCIO says so by name when the transform is used
  }
  std::error_code ec;
  if (!fs::is_regular_file(resolved, ec))
    fail(path, "a FileTransform reads " + excerpt(resolved, 120) + ", which is not a regular file (a device, FIFO or folder)");
  const std::uintmax_t size = fs::file_size(resolved, ec);
  if (ec || size > kMaxTransformFileBytes)
    fail(path, "a FileTransform reads " + excerpt(resolved, 120) + " of " + std::to_string(size) + " bytes: at most " +
                   std::to_string(kMaxTransformFileBytes));
}

// check_transform_files over every transform the config holds: colour spaces, looks, view and named transforms.
void check_config_files(const std::string& path, const OCIO::Config& config) {
  const auto check = [&](const OCIO::ConstTransformRcPtr& t) { check_transform_files(path, config, t); };
  for (int k = 0; k < config.getNumColorSpaces(OCIO::SEARCH_REFERENCE_SPACE_ALL, OCIO::COLORSPACE_ALL); ++k) {
    const auto space = config.getColorSpace(config.getColorSpaceNameByIndex(OCIO::SEARCH_REFERENCE_SPACE_ALL, OCIO::COLORSPACE_ALL, k));
    if (!space) continue;
    check(space->getTransform(OCIO::COLORSPACE_DIR_TO_REFERENCE));
    check(space->getTransform(OCIO::COLORSPACE_DIR_FROM_REFERENCE));
  }
  for (int k = 0; k < config.getNumLooks(); ++k)
    if (const auto look = config.getLook(config.getLookNameByIndex(k))) check(look->getTransform()), check(look->getInverseTransform());
  for (int k = 0; k < config.getNumViewTransforms(); ++k)
    if (const auto view = config.getViewTransform(config.getViewTransformNameByIndex(k)))
      check(view->getTransform(OCIO::VIEWTRANSFORM_DIR_TO_REFERENCE)), check(view->getTransform(OCIO::VIEWTRANSFORM_DIR_FROM_REFERENCE));
  for (int k = 0; k < config.getNumNamedTransforms(OCIO::NAMEDTRANSFORM_ALL); ++k)
    if (const auto named = config.getNamedTransform(config.getNamedTransformNameByIndex(OCIO::NAMEDTRANSFORM_ALL, k)))
      check(named->getTransform(OCIO::TRANSFORM_DIR_FORWARD)), check(named->getTransform(OCIO::TRANSFORM_DIR_INVERSE));
}

}  // namespace

ColorConfig::ColorConfig(const std::string& path) {
  path_ = path;
  if (path_.empty())
    if (const char* env = std::getenv("OCIO"); env && *env) path_ = env;
  if (path_.empty()) return;
  std::error_code ec;
  if (std::filesystem::is_directory(path_, ec)) fail(path_, "is a folder, not an OpenColorIO config (from --ocio-config or $OCIO)");
  if (std::filesystem::exists(path_, ec) && !std::filesystem::is_regular_file(path_, ec))
    fail(path_, "is not a regular file, so not an OpenColorIO config (from --ocio-config or $OCIO)");
  if (!std::filesystem::is_regular_file(path_, ec)) fail(path_, "no such OpenColorIO config (from --ocio-config or $OCIO)");
  try {
    // Studio configs list inactive spaces they do not define; OCIO warns of each on stderr.
    OCIO::SetLoggingLevel(OCIO::LOGGING_LEVEL_NONE);
    auto opaque = std::make_shared<Opaque>();
    opaque->config = OCIO::Config::CreateFromFile(path_.c_str());
    opaque->config->validate();
    check_config_files(path_, *opaque->config);
    config_ = std::move(opaque);
  } catch (const OCIO::Exception& e) {
    fail(path_, std::string("not a valid OpenColorIO config: ") + excerpt(e.what(), 200));
  }
}

ColorConfig::~ColorConfig() = default;

ColorMatrix ColorConfig::from_rec709(const std::string& space) const {
  if (space == kRec709Space && !config_) return ColorMatrix(1.0);
  if (!config_) fail(space, "a colour space other than lin_rec709 needs an OpenColorIO config (--ocio-config or $OCIO)");
  const OCIO::ConstConfigRcPtr& config = config_->config;
  for (const std::string& name : {std::string(kRec709Space), space})
    if (!config->getColorSpace(name.c_str())) fail(path_, "the config has no colour space '" + excerpt(name, 80) + "'");
  if (config->getColorSpace(space.c_str())->isData())
    fail(path_, "colour space '" + excerpt(space, 80) + "' is data, not colour (a working space must be an RGB colour space)");
  ColorMatrix m(0.0);
  try {
    const auto cpu = config->getProcessor(kRec709Space, space.c_str())->getDefaultCPUProcessor();
    for (int k = 0; k < 3; ++k) {
      float column[3] = {0.0f, 0.0f, 0.0f};
      column[k] = 1.0f;
      cpu->applyRGB(column);
      m[k] = Rgb(column[0], column[1], column[2]);
    }
    // A linear space maps every colour by the matrix of the unit vectors; a log or display space does not.
    for (const Rgb probe : {Rgb(0.5, 0.25, 2.0), Rgb(0.01, 0.002, 0.03)}) {
      float c[3] = {float(probe.r), float(probe.g), float(probe.b)};
      cpu->applyRGB(c);
      const Rgb expected = m * probe;
      for (int k = 0; k < 3; ++k)
        if (std::abs(c[k] - expected[k]) > 1e-4 * (1.0 + std::abs(expected[k])))
          fail(path_, "colour space '" + excerpt(space, 80) + "' is not linear (a working space must be)");
    }
  } catch (const OCIO::Exception& e) {
    fail(path_, "cannot convert lin_rec709 to '" + excerpt(space, 80) + "': " + excerpt(e.what(), 200));
  }
  if (!std::isfinite(glm::determinant(m)) || std::abs(glm::determinant(m)) < 1e-6)
    fail(path_, "colour space '" + excerpt(space, 80) + "' is not an RGB space (its matrix from lin_rec709 is singular)");
  return m;
}

}  // namespace facetfit
