// MERL .binary reader: header, dimensions, truncation, NaN and negative values.
#include "fuzz_input.h"
#include "io/merl.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return facetfit::fuzz::run(data, size, ".binary", [](const std::string& path) {
    for (const auto at : {facetfit::HalfDiffTable::BinPoint::start, facetfit::HalfDiffTable::BinPoint::center})
      (void)facetfit::HalfDiffTable::read(path, at);
  });
}
