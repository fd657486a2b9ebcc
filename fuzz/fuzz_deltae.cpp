// `facetfit deltae` lines: each line of the input parsed as a Lab pair, and its Delta E computed.
#include <string>

#include "color/ciede2000.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    try {
      const auto v = facetfit::parse_lab_pair(text.substr(start, end - start), "line");
      (void)facetfit::ciede2000({v[0], v[1], v[2]}, {v[3], v[4], v[5]});
    } catch (const facetfit::Error&) {
    }
    start = end + 1;
  }
  return 0;
}
