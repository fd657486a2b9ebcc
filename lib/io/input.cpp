#include "io/input.h"

#include <glob.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <filesystem>

#include "core/error.h"
#include "io/rgl.h"
#include "io/utia.h"
#include "model/builtin.h"

namespace facetfit {

namespace fs = std::filesystem;

namespace {

// The input formats, each by its extension with its reader: the one list every command consults.
struct InputFormat {
  const char* extension;
  std::shared_ptr<const Brdf> (*read)(const std::string& path, HalfDiffTable::BinPoint merl_bins);
};
constexpr InputFormat kInputFormats[] = {
    {".binary", [](const std::string& p, HalfDiffTable::BinPoint b) -> std::shared_ptr<const Brdf> { return std::make_shared<HalfDiffTable>(HalfDiffTable::read(p, b)); }},
    {".bsdf", [](const std::string& p, HalfDiffTable::BinPoint) -> std::shared_ptr<const Brdf> { return std::make_shared<RglBsdf>(RglBsdf::read(p)); }},
    {".bin", [](const std::string& p, HalfDiffTable::BinPoint) -> std::shared_ptr<const Brdf> { return std::make_shared<UtiaBrdf>(UtiaBrdf::read(p)); }},
};

const InputFormat* input_format(const fs::path& p) {
  for (const InputFormat& f : kInputFormats)
    if (p.extension() == f.extension) return &f;
  return nullptr;
}

bool is_supported_file(const fs::path& p) { return input_format(p) != nullptr; }

}  // namespace

bool is_measurement(const std::string& source) { return is_builtin(source) || is_supported_file(source); }

bool is_builtin(const std::string& source) { return source.compare(0, std::string(kBuiltinPrefix).size(), kBuiltinPrefix) == 0; }

std::string resolve_source(const std::string& base_dir, const std::string& source) {
  if (is_builtin(source) || fs::path(source).is_absolute()) return source;
  return (fs::path(base_dir) / source).lexically_normal().string();
}

std::optional<HalfDiffTable::BinPoint> parse_bin_point(const std::string& name) {
  if (name == "start") return HalfDiffTable::BinPoint::start;
  if (name == "center") return HalfDiffTable::BinPoint::center;
  return std::nullopt;
}

const char* to_string(HalfDiffTable::BinPoint at) { return at == HalfDiffTable::BinPoint::start ? "start" : "center"; }

std::shared_ptr<const Brdf> load_brdf(const std::string& source, HalfDiffTable::BinPoint merl_bins) {
  if (is_builtin(source)) {
    const std::string name = source.substr(std::string(kBuiltinPrefix).size());
    const auto material = find_builtin(name);
    if (!material) fail(source, "no such built-in material (facetfit list-builtins shows them)");
    return material->brdf;
  }
  const fs::path path(source);
  if (const InputFormat* format = input_format(path)) return format->read(source, merl_bins);
  std::error_code ec;
  if (fs::is_directory(path, ec)) fail(source, "is a folder with no supported material file");
  if (!fs::exists(path, ec)) fail(source, "cannot open: no such file");
  std::string supported;
  for (const InputFormat& f : kInputFormats) supported += std::string(f.extension) + ", ";
  fail(source, "unsupported format '" + path.extension().string() + "' (supported: " + supported + "builtin:NAME)");
}

HalfDiffTable table_of(const Brdf& source) {
  if (const auto* table = dynamic_cast<const HalfDiffTable*>(&source)) return *table;
  if (const auto* reader = dynamic_cast<const SelfTabulating*>(&source)) return reader->table();
  return HalfDiffTable::tabulate(source);
}

HalfDiffTable load_table(const std::string& source, HalfDiffTable::BinPoint merl_bins) {
  // A MERL file is read as it is (not through load_brdf, whose shared copy would double the 17 MB).
  if (!is_builtin(source) && fs::path(source).extension() == ".binary") return HalfDiffTable::read(source, merl_bins);
  return table_of(*load_brdf(source, merl_bins));
}

std::vector<std::string> expand_inputs(const std::vector<std::string>& args) {
  std::vector<std::string> out;
  for (const std::string& arg : args) {
    std::error_code ec;
    if (arg == kBuiltinPrefix) {
      for (const auto& m : builtin_materials()) out.push_back(kBuiltinPrefix + m.name);
    } else if (!is_builtin(arg) && fs::is_directory(arg, ec)) {
      std::vector<std::string> files;
      for (const auto& entry : fs::directory_iterator(arg, ec))
        if (entry.is_regular_file(ec) && is_supported_file(entry.path())) files.push_back(entry.path().string());
      std::sort(files.begin(), files.end());
      if (files.empty()) out.push_back(arg);  // reported when loaded
      out.insert(out.end(), files.begin(), files.end());
    } else if (arg.find_first_of("*?[") != std::string::npos && !fs::exists(arg, ec)) {
      // A glob the shell did not expand (quoted, or from a script).
      glob_t g{};
      if (::glob(arg.c_str(), 0, nullptr, &g) == 0) {
        for (std::size_t k = 0; k < g.gl_pathc; ++k) out.push_back(g.gl_pathv[k]);
      } else {
        out.push_back(arg);  // matches nothing: reported when loaded
      }
      ::globfree(&g);
    } else {
      out.push_back(arg);
    }
  }
  return out;
}

void require_regular_file(const std::string& path) {
  std::error_code ec;
  if (fs::exists(path, ec) && !fs::is_regular_file(path, ec)) fail(path, "not a regular file");
}

std::string source_name(const std::string& source) {
  if (is_builtin(source)) return source.substr(std::string(kBuiltinPrefix).size());
  return fs::path(source).stem().string();
}

}  // namespace facetfit
