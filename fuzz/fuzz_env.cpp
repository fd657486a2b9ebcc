// Environment maps (EXR through OpenEXR, any other format through OpenImageIO), under a 256 MiB memory budget, then a sample.
#include "fuzz_input.h"
#include "render/environment.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return facetfit::fuzz::run(data, size, ".exr", [](const std::string& path) {
    const facetfit::Environment env = facetfit::Environment::load(path, std::uint64_t(256) << 20);
    (void)env.sample(0.3, 0.7);
  });
}
