// The reference renderer: render/tracer.h for visibility, direct lighting from the environment (a map
// with multiple importance sampling, a constant one by BRDF sampling) and the scene's lights, oneTBB over
// tiles, a fixed random sequence per pixel (the same scene and settings give the same image on any number
// of threads).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "render/scene.h"

namespace facetfit {

struct RenderSettings {
  int spp = 0;                // 0: the scene's
  std::uint64_t seed = 0;     // 0: the scene's
  int passes = 4;             // samples are added in passes (progressive), each over the whole image
  // A tile at a time: rays as streams (render/tracer.h, render/sphere_batch.h) and shading in SIMD lanes
  // (render/wavefront.h); false: one ray and one evaluation at a time (the same image, the reference the
  // stream path is tested against).
  bool ray_streams = true;
  // Bytes the image buffers, textures, environment map and meshes may take together (core/memory_budget.h);
  // 0: half of the machine's memory. A scene over it is refused before the images are allocated, a mesh as
  // its file is read.
  std::uint64_t max_memory = 0;
  std::function<void(int done_passes, int passes)> progress;  // optional
};

struct RenderedImage {
  int width = 0, height = 0;
  std::vector<float> rgba;  // linear, in `colorspace`; alpha = coverage of the objects
  std::string colorspace = kRec709Space;  // the scene's working space, and its matrix from lin_rec709
  ColorMatrix from_rec709{1.0};
  int spp = 0;
  double seconds = 0.0;

  std::vector<float> rgb() const;  // the colour alone, interleaved
};

// Loads what the scene needs (its environment, and only the materials its objects use) and renders.
// Throws Error for anything it cannot load, and for a scene over settings.max_memory.
RenderedImage render(const SceneDesc& scene, const RenderSettings& settings = {});

// Linear EXR (R, G, B, A, float) with the given string metadata (as facetfit:KEY), the chromaticities of
// its colour space and the space's name (oiio:ColorSpace), through a temporary file.
void write_exr(const std::string& path, const RenderedImage& image, const std::vector<std::pair<std::string, std::string>>& metadata);

}  // namespace facetfit
