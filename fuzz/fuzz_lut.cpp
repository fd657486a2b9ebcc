// LUT textures (OpenEXR, then facetfit's metadata and table checks), then an
// evaluation and a sample of the model it accepted.
// max_len: 262144 (a LUT with sampling tables is ~100 KB)
#include "core/vec.h"
#include "fuzz_input.h"
#include "lut/lut.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return facetfit::fuzz::run(data, size, ".exr", [](const std::string& path) {
    const facetfit::Lut lut = facetfit::read_lut(path);
    const facetfit::TabulatedMicrofacet model = lut.model();
    const facetfit::Vec3 o = facetfit::spherical_direction(0.4, 2.0);
    for (const double theta : {0.0, 0.7, 1.5}) (void)model.eval(o, facetfit::spherical_direction(theta, 0.3));
    if (model.can_sample()) (void)model.sample(o, 0.3, 0.7);
  });
}
