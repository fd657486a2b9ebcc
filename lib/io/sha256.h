// SHA-256 of files and bytes (OpenSSL), as lowercase hex: the identity of a measured source in LUT
// metadata and in the bake cache.
#pragma once

#include <cstddef>
#include <string>

namespace facetfit {

std::string sha256_hex(const void* data, std::size_t size);
// Throws Error("<path>: <problem>") when the file cannot be read.
std::string sha256_file(const std::string& path);

}  // namespace facetfit
