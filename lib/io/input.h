// Material inputs named on a command line, whatever their format, as MERL-layout tables.
//
// Sources: a MERL `.binary` file, an RGL `.bsdf` file, a UTIA `.bin` file (anisotropic: tabulated as its
// azimuthal mean, UtiaBrdf::azimuthal_mean) or `builtin:NAME` (all but MERL tabulated into MERL layout
// on load). Folders expand to the
// supported files they hold, sorted by name.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "io/merl.h"

namespace facetfit {

constexpr const char* kBuiltinPrefix = "builtin:";

// Whether `source` names a measurement: builtin:NAME, or a file of an input format by its extension
// (.binary, .bsdf, .bin).
bool is_measurement(const std::string& source);

// Loads one source. Throws Error("<source>: <problem>"). `merl_bins`: which point of its bins a MERL
// file's values stand for (io/merl.h).
HalfDiffTable load_table(const std::string& source, HalfDiffTable::BinPoint merl_bins = HalfDiffTable::BinPoint::start);

// One source as it is, at its own resolution: the MERL table, the RGL file (symmetric slices), the UTIA
// file or the analytic built-in. Throws Error("<source>: <problem>").
std::shared_ptr<const Brdf> load_brdf(const std::string& source, HalfDiffTable::BinPoint merl_bins = HalfDiffTable::BinPoint::start);

// The MERL-layout table the fits see of a loaded source: a MERL table as it is, a UTIA file as its
// azimuthal mean with its own back-scattering (HalfDiffTable::source_backscatter), anything else tabulated.
// load_table(source) is table_of(*load_brdf(source)), without the copy for MERL files.
HalfDiffTable table_of(const Brdf& source);

// "start" or "center"; nullopt otherwise.
std::optional<HalfDiffTable::BinPoint> parse_bin_point(const std::string& name);
const char* to_string(HalfDiffTable::BinPoint at);

// Folders become the supported files inside them, globs their matches; `builtin:` alone becomes every
// built-in material.
// Anything else is passed through (and fails later, with its own message, if it is not loadable).
std::vector<std::string> expand_inputs(const std::vector<std::string>& args);

// Whether a source names a built-in material (builtin:NAME).
bool is_builtin(const std::string& source);

// A source named inside a file (a scene): relative paths resolve against `base_dir`; built-ins and
// absolute paths stay as they are.
std::string resolve_source(const std::string& base_dir, const std::string& source);

// Throws Error("<path>: not a regular file") for a device, a FIFO or a folder, which a reader would read
// without end (/dev/zero) or probe forever; a missing path is left to the reader's own message.
void require_regular_file(const std::string& path);

// The short name of a source: file stem, or the built-in's name.
std::string source_name(const std::string& source);

}  // namespace facetfit
