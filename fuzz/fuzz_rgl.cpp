// RGL .bsdf tensor-file reader, then an evaluation of what it accepted.
// max_len: 1048576 (a real RGL material is 0.66 MB)
#include "fuzz_input.h"
#include "core/vec.h"
#include "io/rgl.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return facetfit::fuzz::run(data, size, ".bsdf", [](const std::string& path) {
    const facetfit::RglBsdf bsdf = facetfit::RglBsdf::read(path);
    for (const double theta : {0.0, 0.7, 1.5})
      (void)bsdf.eval(facetfit::spherical_direction(0.4, 2.0), facetfit::spherical_direction(theta, 0.3));
  });
}
