// Fits a material with an installed facetfit, bakes its LUT and reads it back: the library, its headers
// and its dependencies as a consumer gets them from find_package(facetfit).
#include <facetfit/core/error.h>
#include <facetfit/fit/fit.h>
#include <facetfit/io/input.h>
#include <facetfit/lut/lut.h>

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
  } catch (const facetfit::Error& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 1;
  }
  return 0;
}
