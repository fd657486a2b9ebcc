#include "color/colorspace.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <glm/matrix.hpp>

#include "color/colorspace_ocio.h"
#include "core/error.h"

namespace facetfit {

ColorConfig::ColorConfig(const std::string& path) {
  path_ = path;
  if (path_.empty())
    if (const char* env = std::getenv("OCIO"); env && *env) path_ = env;
  if (path_.empty()) return;
  if (!std::filesystem::is_regular_file(path_)) fail(path_, "no such OpenColorIO config (from --ocio-config or $OCIO)");
  try {
    // Studio configs list inactive spaces they do not define; OCIO warns of each on stderr.
    OCIO::SetLoggingLevel(OCIO::LOGGING_LEVEL_NONE);
    auto opaque = std::make_shared<Opaque>();
    opaque->config = OCIO::Config::CreateFromFile(path_.c_str());
    opaque->config->validate();
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
