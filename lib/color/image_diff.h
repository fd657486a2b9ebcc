// Per-pixel colour difference of two images and what the reports show of it: the CIE Delta E 2000 of
// each pixel through the display chain (docs/colour.md), a false-colour heatmap, display-referred PNGs.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "color/display.h"

namespace facetfit {

// The heatmap's fixed scale: Delta E 2000 from 0 to kHeatmapMax across the colour map, saturating beyond,
// so that two heatmaps compare by eye. 10 spans "invisible" (< 1) to "obviously different" (> 5).
constexpr double kHeatmapMax = 10.0;

struct ImageDiff {
  std::vector<float> delta_e;  // per pixel; 0 outside the mask
  double mean = 0.0, max = 0.0;
  std::size_t pixels = 0;      // pixels in the mask
};

// a and b: interleaved RGB of `pixels` pixels, scene-linear (display_referred false: the display transform
// is applied) or display code values already. Only pixels with mask[p] count.
ImageDiff image_delta_e(std::vector<float> a, bool a_display_referred, std::vector<float> b, bool b_display_referred,
                        const std::vector<bool>& mask, const DisplayTransform& display);

// The heatmap's colour of a Delta E: viridis from 0 to kHeatmapMax, 8-bit RGB.
std::array<std::uint8_t, 3> heatmap_colour(double delta_e);

// Viridis from 0 to kHeatmapMax, black outside the mask; an 8-bit PNG through a temporary file.
void write_heatmap_png(const std::string& path, int width, int height, const std::vector<float>& delta_e,
                       const std::vector<bool>& mask);

// A scene-linear image (interleaved, `channels` per pixel, RGB first) through the display transform, as an
// 8-bit sRGB PNG through a temporary file.
void write_display_png(const std::string& path, const float* pixels, int width, int height, int channels,
                       const DisplayTransform& display);

}  // namespace facetfit
