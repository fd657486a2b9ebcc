// What ColorConfig holds of OpenColorIO: for the files that call OCIO, never installed.
#pragma once

#include <OpenColorIO/OpenColorIO.h>

#include "color/ocio_config.h"

namespace OCIO = OCIO_NAMESPACE;

namespace facetfit {

struct ColorConfig::Opaque {
  OCIO::ConstConfigRcPtr config;
};

}  // namespace facetfit
