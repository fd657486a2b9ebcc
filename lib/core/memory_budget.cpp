#include "core/memory_budget.h"

#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "core/error.h"

namespace facetfit {

std::uint64_t default_memory_budget() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page <= 0) return std::uint64_t(1) << 30;
  return std::uint64_t(pages) * std::uint64_t(page) / 2;
}

namespace {

// Whether [begin, end) is written as a decimal number: strtod also reads hexadecimal ("0x10G" was 16 GiB)
// and skips leading spaces.
bool decimal_number(const char* begin, const char* end) {
  for (const char* c = begin; c != end; ++c)
    if (!std::isdigit(static_cast<unsigned char>(*c)) && *c != '.' && *c != 'e' && *c != 'E' && *c != '+' && *c != '-') return false;
  return true;
}

// Bytes per unit of a size's suffix: K, M, G or T, optionally followed by iB or B; or B; or nothing.
// Null for any other suffix.
std::optional<double> unit_scale(std::string unit) {
  if (unit.size() >= 3 && unit.compare(unit.size() - 2, 2, "iB") == 0) unit.resize(unit.size() - 2);
  else if (unit.size() == 2 && unit.back() == 'B') unit.pop_back();
  if (unit == "K" || unit == "k") return 1024.0;
  if (unit == "M") return 1024.0 * 1024.0;
  if (unit == "G") return 1024.0 * 1024.0 * 1024.0;
  if (unit == "T") return 1024.0 * 1024.0 * 1024.0 * 1024.0;
  if (!unit.empty() && unit != "B") return std::nullopt;
  return 1.0;
}

}  // namespace

std::optional<std::uint64_t> parse_byte_size(const std::string& text) {
  if (text.empty() || text.size() > 32) return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || !std::isfinite(value) || value <= 0.0) return std::nullopt;
  if (!decimal_number(text.c_str(), end)) return std::nullopt;
  const std::optional<double> scale = unit_scale(end);
  if (!scale) return std::nullopt;
  const double bytes = value * *scale;
  if (!(bytes >= 1.0 && bytes < 1.8e19)) return std::nullopt;
  return static_cast<std::uint64_t>(bytes);
}

std::string format_bytes(std::uint64_t bytes) {
  char text[64];
  if (bytes >= (std::uint64_t(1) << 30)) std::snprintf(text, sizeof text, "%.1f GiB", double(bytes) / double(std::uint64_t(1) << 30));
  else if (bytes >= (std::uint64_t(1) << 20)) std::snprintf(text, sizeof text, "%.1f MiB", double(bytes) / double(std::uint64_t(1) << 20));
  else if (bytes >= 1024) std::snprintf(text, sizeof text, "%.1f KiB", double(bytes) / 1024.0);
  else std::snprintf(text, sizeof text, "%llu bytes", static_cast<unsigned long long>(bytes));
  return text;
}

void check_memory(const std::string& what, const std::string& needing, std::uint64_t need, std::uint64_t budget) {
  if (need > budget) fail(what, needing + " needs " + format_bytes(need) + ", over the memory budget of " + format_bytes(budget));
}

}  // namespace facetfit
