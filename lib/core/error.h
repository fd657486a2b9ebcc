// facetfit reports every bad input as an Error whose message is one line: "WHAT: PROBLEM".
#pragma once

#include <stdexcept>
#include <string>

namespace facetfit {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Text from the input as a message may quote it: printable ASCII (others as '?', so that the message stays
// one line), at most `max` characters, then "..." where it was cut.
inline std::string excerpt(const std::string& text, std::size_t max) {
  std::string out;
  for (std::size_t k = 0; k < text.size() && k < max; ++k) {
    const unsigned char c = static_cast<unsigned char>(text[k]);
    out += c >= 0x20 && c < 0x7f ? char(c) : '?';
  }
  if (text.size() > max) out += "...";
  return out;
}

// Throws Error("<what>: <problem>"); `what` is usually a file path.
[[noreturn]] inline void fail(const std::string& what, const std::string& problem) {
  throw Error(what + ": " + problem);
}

}  // namespace facetfit
