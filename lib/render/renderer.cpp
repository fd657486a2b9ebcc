#include "render/renderer.h"

#include <chrono>

#include "io/image_file.h"
#include "render/integrator.h"

namespace facetfit {

RenderedImage render(const SceneDesc& desc, const RenderSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  RenderedImage image = Integrator(desc, settings).Render();
  image.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return image;
}

std::vector<float> RenderedImage::rgb() const {
  std::vector<float> out(std::size_t(width) * height * 3);
  for (std::size_t p = 0; p < out.size() / 3; ++p)
    for (int c = 0; c < 3; ++c) out[3 * p + c] = rgba[4 * p + c];
  return out;
}

void write_exr(const std::string& path, const RenderedImage& image, const std::vector<std::pair<std::string, std::string>>& metadata) {
  ImageSpec spec(image.width, image.height, {"R", "G", "B", "A"});
  spec.linear_space = image.colorspace;
  spec.linear_chromaticities = chromaticities(image.from_rec709);
  // The matrix too: chromaticities alone do not say how the white was adapted (ACEScg's from D65 to D60).
  if (image.colorspace != kRec709Space) spec.set("facetfit:colorspace_matrix", matrix_text(image.from_rec709));
  for (const auto& [k, v] : metadata) spec.set("facetfit:" + k, v);
  write_image_atomic(path, spec, image.rgba.data());
}

}  // namespace facetfit
