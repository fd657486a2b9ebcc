// Wavefront OBJ meshes of scenes.
#include <vector>

#include "fuzz_input.h"
#include "render/tracer.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return facetfit::fuzz::run(data, size, ".obj", [](const std::string& path) {
    std::vector<float> positions;
    std::vector<unsigned> indices;
    facetfit::read_obj(path, positions, indices);
  });
}
