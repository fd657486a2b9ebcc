// What every harness shares: the bytes libFuzzer hands over, as a file of the reader's kind (the readers
// take paths, as the command does), and the rule that an input may only ever cause facetfit::Error.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "core/error.h"

namespace facetfit::fuzz {

// A file holding `data`, named with `extension` (readers dispatch on it), private to this process.
inline std::string write_input(const uint8_t* data, size_t size, const char* extension) {
  const std::string path = "/tmp/facetfit-fuzz-" + std::to_string(::getpid()) + extension;
  if (FILE* f = std::fopen(path.c_str(), "wb")) {
    if (size > 0) std::fwrite(data, 1, size, f);
    std::fclose(f);
  }
  return path;
}

// Runs `read` on the input: a facetfit::Error is the expected answer to bad bytes; anything else
// (another exception, a crash, a sanitizer report, a hang) is a finding.
template <class Read>
int run(const uint8_t* data, size_t size, const char* extension, Read read) {
  const std::string path = write_input(data, size, extension);
  try {
    read(path);
  } catch (const Error&) {
  }
  ::unlink(path.c_str());
  return 0;
}

}  // namespace facetfit::fuzz
