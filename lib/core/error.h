// facetfit reports every bad input as an Error whose message is one line: "WHAT: PROBLEM".
#pragma once

#include <stdexcept>
#include <string>

namespace facetfit {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws Error("<what>: <problem>"); `what` is usually a file path.
[[noreturn]] inline void fail(const std::string& what, const std::string& problem) {
  throw Error(what + ": " + problem);
}

}  // namespace facetfit
