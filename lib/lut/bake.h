// Baking: measured materials to LUT textures and JSON sidecars, cached by content.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/rgb_space.h"
#include "fit/fit.h"
#include "fit/recommend.h"

namespace facetfit {

struct BakeOptions {
  FitOptions fit;
  double tolerance = kDefaultTolerance;  // how much farther a parametric fit may be and still be recommended (fit/recommend.h)
  bool with_sampling = true;
  bool force = false;  // bake even when the cache says the outputs are current
  // The space of the LUT's colours (core/rgb_space.h) and its matrix from lin_rec709, the fit's space.
  std::string colorspace = kRec709Space;
  ColorMatrix from_rec709{1.0};
};

struct BakeOutcome {
  enum class Status { baked, cached, failed };
  Status status = Status::failed;
  std::string source;
  std::string name;   // output stem: DIR/NAME.exr, DIR/NAME.json
  std::string error;  // one line, for failed
  nlohmann::json record;  // the sidecar's content (baked or cached)
  double seconds = 0.0;
};

// The identity of a source in LUT metadata: SHA-256 of a file's bytes, of a built-in's name.
std::string source_sha256(const std::string& source);

// The key under which a bake of the source with this `sha256` with these settings is cached.
std::string bake_cache_key(const std::string& sha256, const BakeOptions& options);

// Bakes one source into out_dir (which must exist). Never throws for a bad input: the outcome says why.
BakeOutcome bake_material(const std::string& source, const std::string& name, const std::string& out_dir,
                          const BakeOptions& options, const Fitter& fitter);

}  // namespace facetfit
