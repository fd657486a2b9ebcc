// The memory a render may take (its image buffers and environment map), checked before anything is
// allocated so that a too-large request is one clear line, not std::bad_alloc or the OOM killer.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace facetfit {

// Half of the machine's physical memory (1 GiB where it cannot be read).
std::uint64_t default_memory_budget();

// "512M", "4G", "1.5G", "1048576" (bytes), with K, M, G or T (powers of 1024, optional trailing B or iB);
// nullopt for anything else or zero.
std::optional<std::uint64_t> parse_byte_size(const std::string& text);

// "512 bytes", "2.5 KiB", "12.3 MiB", "4.0 GiB".
std::string format_bytes(std::uint64_t bytes);

// Throws Error("<what>: <needing> needs <need>, over the memory budget of <budget>") when need > budget.
void check_memory(const std::string& what, const std::string& needing, std::uint64_t need, std::uint64_t budget);

}  // namespace facetfit
