// The colour spaces of a studio's OpenColorIO config: the matrix from lin_rec709 to a working space
// (ACEScg, say), for a bake or a render in that space (core/rgb_space.h).
#pragma once

#include <memory>
#include <string>

#include "core/rgb_space.h"

namespace facetfit {

class ColorConfig {
 public:
  // `path`, else $OCIO, else none: then only kRec709Space is known. Throws Error naming the file when it
  // cannot be read or is not a valid config.
  explicit ColorConfig(const std::string& path = "");
  ~ColorConfig();

  bool has_config() const { return config_ != nullptr; }
  const std::string& path() const { return path_; }
  // The matrix from kRec709Space to `space` (the identity for kRec709Space itself), read off the config's
  // processor and checked to be linear. Throws Error naming the space when the config lacks it or when its
  // conversion is not a 3x3 matrix (a log or display space).
  ColorMatrix from_rec709(const std::string& space) const;

  struct Opaque;  // OpenColorIO's config (color/ocio_handles.h)
  const Opaque* opaque() const { return config_.get(); }

 private:
  std::string path_;
  std::shared_ptr<const Opaque> config_;
};

}  // namespace facetfit
