// The facetfit subcommands. Each registers itself on the app and reports its exit status through
// `status`: 0 success, 1 some input failed, 2 usage (parser errors included), 3 `report
// --fail-on-regression` found regressions (and nothing failed).
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>
#include <string>

#include "color/ocio_config.h"
#include "color/display.h"
#include "core/rgb_space.h"
#include "fit/fit.h"

namespace facetfit::cli {

// What a command prints besides its results and errors: global -q (errors, warnings and the results
// themselves only: no progress, no summaries) and -v (also the settings and per-item timings).
enum class Verbosity { quiet, normal, verbose };

// The state one command line runs with: its exit status and verbosity.
struct Context {
  int status = 0;
  Verbosity verbosity = Verbosity::normal;
  bool quiet() const { return verbosity == Verbosity::quiet; }
  bool verbose() const { return verbosity == Verbosity::verbose; }
};

// The fit settings every command that fits takes, as given on the command line.
struct FitSettings {
  std::string smith = "correlated";
  int resolution = 90;
  double iteration_tolerance = 1e-10;
  int max_iterations = 1000;
  std::string refine = "full";
  std::string merl_bins = "start";
  std::string closure_fresnel = "f82";
};
void add_fit_settings(CLI::App* cmd, FitSettings& settings);
// --tolerance, the one definition of fit/recommend.h: how much farther from the measurement a GGX or
// Beckmann fit may be than the tabulated representation and still be the recommended one.
void add_tolerance_option(CLI::App* cmd, double& tolerance);
// The FitOptions they name, or nullopt after reporting a usage error (status 2).
std::optional<FitOptions> fit_options(const FitSettings& settings, int& status);

// The working colour space of a bake or a render (core/rgb_space.h): --working-space, from the config of
// --ocio-config or $OCIO. In the command module (bin/color_commands.cpp): it reads OpenColorIO.
// And the pictures' display and view (--display, --view: render --png, the report's pictures).
struct ColorSettings {
  std::string working_space = kRec709Space;
  std::string ocio_config;
  std::string display, view;
  // The config of --ocio-config or $OCIO, read once per command; throws Error (one line) when it is broken.
  ColorConfig config() const;
  // The working space's matrix from lin_rec709; throws Error (one line) for an unknown space.
  ColorMatrix from_rec709(const ColorConfig& config) const;
  // The pictures of pixels in `space` (matrix `from_rec709`): the config's display and view, or without
  // --display the sRGB display of their Rec.709 colour. Throws Error (one line).
  DisplayTransform pictures(const ColorConfig& config, const std::string& space, const ColorMatrix& from_rec709) const;
};
void add_working_space_options(CLI::App* cmd, ColorSettings& settings);
void add_view_options(CLI::App* cmd, ColorSettings& settings);

// A check for a real-valued option: a finite number in [lo, hi] (CLI::Range lets NaN through: every
// comparison with it is false).
CLI::Validator finite_in(double lo, double hi);
// A check for an unsigned 64-bit option: decimal digits only, within range (CLI11 takes "-1" and 2^64 and
// wraps them).
CLI::Validator uint64_text();

// --max-memory SIZE ("4G", "512M"): what `what` may take (default half of the machine's memory); a bad size
// is a usage error.
void add_max_memory_option(CLI::App* cmd, std::uint64_t& bytes, const std::string& what = "a render's image and environment map");

void add_fit_command(CLI::App& app, Context& ctx);
void add_convert_command(CLI::App& app, Context& ctx);
void add_builtins_command(CLI::App& app, Context& ctx);
void add_bake_command(CLI::App& app, Context& ctx);
void add_info_command(CLI::App& app, Context& ctx);
void add_render_command(CLI::App& app, Context& ctx);
void add_deltae_command(CLI::App& app, Context& ctx);
void add_diff_command(CLI::App& app, Context& ctx);
void add_report_command(CLI::App& app, Context& ctx);
void add_export_command(CLI::App& app, Context& ctx);

// With -v: "facetfit: COMMAND: <settings>" on stderr (the fit settings and the thread count).
void report_settings(const Context& ctx, const std::string& command, const FitOptions& options);

// "facetfit: error: <message>" on stderr, one line.
void report_error(const std::string& message);

// Parses and runs one command line on an app holding the core commands (fit, convert, list-builtins) and
// those `register_more` adds; returns the exit status.
int run_app(int argc, char** argv, void (*register_more)(CLI::App& app, Context& ctx));
// Whether a subcommand is one of the core commands, which need no image I/O, colour or ray tracing.
bool is_core_command(const std::string& name);
// The command the command line names: its first argument past -q, -v and --threads N ("" for none).
std::string command_word(int argc, char** argv);

}  // namespace facetfit::cli
