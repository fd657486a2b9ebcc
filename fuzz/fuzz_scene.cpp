// Scene JSON: parsing and validation of every key (nothing is loaded).
#include "fuzz_input.h"
#include "render/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return facetfit::fuzz::run(data, size, ".json", [](const std::string& path) { (void)facetfit::parse_scene(path); });
}
