// Fits a material with an installed facetfit, bakes its LUT, reads it back and renders it: the library,
// its public headers and its dependencies as a consumer gets them from find_package(facetfit).
#include <facetfit/core/error.h>
#include <facetfit/fit/fit.h>
#include <facetfit/io/input.h>
#include <facetfit/lut/lut.h>
#include <facetfit/render/renderer.h>

#include <cmath>
#include <cstdio>
#include <string>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: consumer INPUT OUT.exr\n");
    return 2;
  }
  try {
    const facetfit::Fitter fitter(facetfit::FitOptions::paper());
    const facetfit::FitResult fit = fitter.fit(facetfit::load_table(argv[1]));
    if (!fit.ok()) throw facetfit::Error(fit.problem);
    facetfit::write_lut(argv[2], facetfit::make_lut(fit, fitter.quadrature(), argv[1], "", 0.02, true));
    const facetfit::Lut lut = facetfit::read_lut(argv[2]);
    std::printf("alpha_ggx %.4f read back %.4f\n", fit.alpha_ggx, lut.meta.alpha_ggx);
    // The LUT on the default scene's sphere, small and quick.
    facetfit::MaterialDesc subject;
    subject.type = "lut";
    subject.file = argv[2];
    facetfit::SceneDesc scene = facetfit::default_scene(subject);
    scene.camera.width = scene.camera.height = 32;
    facetfit::RenderSettings settings;
    settings.spp = 4;
    const facetfit::RenderedImage image = facetfit::render(scene, settings);
    double sum = 0.0;
    for (const float v : image.rgb()) sum += v;
    if (!(std::isfinite(sum) && sum > 0.0)) throw facetfit::Error("the render is black or not finite");
    std::printf("rendered %dx%d, mean %.4f\n", image.width, image.height, sum / double(image.rgb().size()));
  } catch (const facetfit::Error& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 1;
  }
  return 0;
}
