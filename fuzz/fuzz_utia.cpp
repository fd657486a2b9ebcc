// UTIA .bin reader: size, non-finite and negative values, then what the fits read of it (the azimuthal
// mean and the back-scattering samples).
// max_len: 1990656 (a UTIA file is 3 x 6 x 48 x 6 x 48 doubles)
#include "fuzz_input.h"
#include "io/utia.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return facetfit::fuzz::run(data, size, ".bin", [](const std::string& path) {
    const facetfit::UtiaBrdf brdf = facetfit::UtiaBrdf::read(path);
    (void)brdf.azimuthal_mean();
    (void)brdf.backscatter();
    (void)brdf.eval({0.0, 0.6, 0.8}, {0.36, -0.48, 0.8});
  });
}
