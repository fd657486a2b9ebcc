// Helpers shared by the renderer's tests (tests/render/).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "fit/fit.h"
#include "io/image_file.h"
#include "io/input.h"
#include "lut/lut.h"

namespace facetfit::test {

// The paper's fit of the built-in gold GGX 0.15, baked with sampling tables.
inline void write_gold_lut(const std::string& path) {
  const Fitter fitter{FitOptions::paper()};
  write_lut(path, make_lut(fitter.fit(load_table("builtin:gold-ggx-0.15")), fitter.quadrature(), "builtin:gold-ggx-0.15", "x", 0.02, true));
}

// A float RGB image of `width` x `height` with value(x, y) at pixel (x, y), row 0 at the top.
inline void write_texture(const std::string& path, int width, int height, const std::function<Rgb(int, int)>& value) {
  std::vector<float> px;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const Rgb v = value(x, y);
      px.insert(px.end(), {float(v.r), float(v.g), float(v.b)});
    }
  write_image_atomic(path, ImageSpec(width, height, {"R", "G", "B"}), px.data());
}

}  // namespace facetfit::test
