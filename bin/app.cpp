// The facetfit command line: the app every command registers on, and the settings they share.
#include <tbb/global_control.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <vector>

#include "commands.h"
#include "core/error.h"
#include "core/memory_budget.h"
#include "io/input.h"

namespace facetfit::cli {

void report_error(const std::string& message) { std::fprintf(stderr, "facetfit: error: %s\n", message.c_str()); }

void report_settings(const Context& ctx, const std::string& command, const FitOptions& o) {
  if (!ctx.verbose()) return;
  std::fprintf(stderr, "facetfit: %s: refine %s, resolution %d, smith %s, merl-bins %s, closure-fresnel %s, threads %zu\n",
               command.c_str(), to_string(o.refine), o.resolution, to_string(o.smith), to_string(o.merl_bins), to_string(o.closure_fresnel),
               tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

CLI::Validator finite_in(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        double v = 0.0;
        std::size_t used = 0;
        try {
          v = std::stod(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used != text.size() || !std::isfinite(v) || v < lo || v > hi)
          return "'" + text + "' is not a finite number in [" + CLI::detail::to_string(lo) + ", " + CLI::detail::to_string(hi) + "]";
        return "";
      },
      "FINITE in [" + CLI::detail::to_string(lo) + " - " + CLI::detail::to_string(hi) + "]");
}

CLI::Validator uint64_text() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        bool ok = !text.empty() && text.size() <= 20 && text.find_first_not_of("0123456789") == std::string::npos;
        if (ok) {
          errno = 0;
          std::strtoull(text.c_str(), nullptr, 10);
          ok = errno != ERANGE;
        }
        return ok ? "" : "'" + text + "' is not an integer in [0, 18446744073709551615]";
      },
      "UINT64");
}

void add_max_memory_option(CLI::App* cmd, std::uint64_t& bytes, const std::string& what) {
  cmd->add_option_function<std::string>(
         "--max-memory",
         [&bytes](const std::string& text) {
           const auto parsed = parse_byte_size(text);
           if (!parsed) throw CLI::ValidationError("--max-memory", "'" + text + "' is not a size such as 512M or 4G");
           bytes = *parsed;
         },
         "Memory " + what + " may take, e.g. 512M or 4G (default: half of this machine's, " +
             format_bytes(default_memory_budget()) + ")");
}

void add_tolerance_option(CLI::App* cmd, double& tolerance) {
  cmd->add_option("--tolerance", tolerance,
                  "The recommended representation is the cheapest to shade (a GGX or Beckmann fit, then the closures, then "
                  "the tabulated lobe) whose distance from the measurement is at most (1 + T) times the nearest one's (or 0.2 L* units, 0.2 / 116, more)")
      ->check(finite_in(0.0, 1e30))  // what a LUT reader accepts (lut/lut.cpp)
      ->capture_default_str();
}

void add_fit_settings(CLI::App* cmd, FitSettings& s) {
  cmd->add_option("--smith", s.smith,
                  "Masking-shadowing model the fit is consistent with: masking (the paper), correlated "
                  "(height-correlated, as pbrt-v4 and Cycles render), separable")
      ->capture_default_str();
  cmd->add_option("--resolution", s.resolution, "Intervals of the theta = u^2 pi/2 grid (90: MERL's own bins)")
      ->check(CLI::Range(kMinResolution, kMaxResolution))
      ->capture_default_str();
  cmd->add_option("--iteration-tolerance", s.iteration_tolerance, "Power-iteration stop: relative L1 change of the NDF")
      ->check(finite_in(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--max-iterations", s.max_iterations, "Power-iteration limit")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  cmd->add_option("--refine", s.refine,
                  "full: refine body, NDF and Fresnel, and fit GGX and Beckmann, on the whole measurement; "
                  "none: the paper's method alone (power iteration on back-scattering, Fresnel pass, moment alphas)")
      ->capture_default_str();
  cmd->add_option("--merl-bins", s.merl_bins,
                  "Which point of its bin a MERL file's value stands for: start (the lower edge, what facetfit "
                  "writes) or center")
      ->capture_default_str();
  cmd->add_option("--closure-fresnel", s.closure_fresnel,
                  "The closure representation's first lobe: f82 (F82-tint, as Cycles' microfacet_f82_tint) or "
                  "schlick (generalized Schlick like the other lobes: what MaterialX's OSL generator renders exactly)")
      ->capture_default_str();
}

// A flag's parsed value; nullopt after a usage error (status 2) naming the flag, its value and what it takes.
template <class T>
std::optional<T> flag_value(std::optional<T> parsed, const std::string& flag, const std::string& value, const char* accepted,
                            int& status) {
  if (!parsed) {
    report_error(flag + " " + value + ": must be " + accepted);
    status = 2;
  }
  return parsed;
}

std::optional<FitOptions> fit_options(const FitSettings& s, int& status) {
  const auto smith = flag_value(parse_smith(s.smith), "--smith", s.smith, "masking, correlated or separable", status);
  const auto merl_bins = flag_value(parse_bin_point(s.merl_bins), "--merl-bins", s.merl_bins, "start or center", status);
  const auto refine = flag_value(parse_refine(s.refine), "--refine", s.refine, "none or full", status);
  const auto closure_fresnel =
      flag_value(parse_closure_fresnel(s.closure_fresnel), "--closure-fresnel", s.closure_fresnel, "f82 or schlick", status);
  if (!smith || !merl_bins || !refine || !closure_fresnel) return std::nullopt;
  FitOptions options;
  options.smith = *smith;
  options.resolution = s.resolution;
  options.tolerance = s.iteration_tolerance;
  options.max_iterations = s.max_iterations;
  options.merl_bins = *merl_bins;
  options.refine = *refine;
  options.closure_fresnel = *closure_fresnel;
  return options;
}

namespace {

// The edit distance of two short words (insertions, deletions, substitutions).
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

const CLI::App* find_command(const CLI::App& app, const std::string& name) {
  for (const CLI::App* sub : app.get_subcommands({}))
    if (sub->check_name(name)) return sub;
  return nullptr;
}

// A usage error's line: the parser's complaint pointing to the command's own help, or for a command word
// that is no command, that, with the nearest command (within two edits).
std::string usage_error(const CLI::App& app, const std::string& word, const std::string& complaint) {
  if (word.empty() || word[0] == '-') return complaint + " (see facetfit --help)";
  if (find_command(app, word)) return complaint + " (see facetfit " + word + " --help)";
  std::string nearest;
  std::size_t best = 3;
  for (const CLI::App* sub : app.get_subcommands({}))
    if (const std::size_t d = edit_distance(word, sub->get_name()); d < best) best = d, nearest = sub->get_name();
  return "unknown command '" + word + "' (" + (nearest.empty() ? "see facetfit --help" : "did you mean 'facetfit " + nearest + "'?") + ")";
}

}  // namespace

std::string command_word(int argc, char** argv) {
  for (int k = 1; k < argc; ++k) {
    const std::string arg = argv[k];
    if (arg == "--threads") {
      ++k;
      continue;
    }
    if (arg.rfind("--threads=", 0) == 0 || arg == "-q" || arg == "--quiet" || arg == "-v" || arg == "--verbose") continue;
    return arg;
  }
  return "";
}

int run_app(int argc, char** argv, void (*register_more)(CLI::App& app, Context& ctx)) {
  CLI::App app{"facetfit: measured BRDFs to microfacet components (Dupuy et al. 2015, power iterations)", "facetfit"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("facetfit ") + FACETFIT_VERSION + " (" + FACETFIT_BUILD_INFO + ")");
  // --threads N caps every parallel part of every command (TBB's global limit), set as soon as parsed.
  std::unique_ptr<tbb::global_control> threads;
  app.add_option_function<int>(
         "--threads",
         [&](int n) {
           if (n > 0) threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::size_t(n));
         },
         "Threads to use (default: all cores)")
      ->check(CLI::Range(1, 4096))
      ->trigger_on_parse();
  Context ctx;
  app.add_flag_callback("-q,--quiet", [&ctx] { ctx.verbosity = Verbosity::quiet; }, "Print only results, warnings and errors");
  app.add_flag_callback("-v,--verbose", [&ctx] { ctx.verbosity = Verbosity::verbose; }, "Also print settings and per-item timings");
  add_fit_command(app, ctx);
  add_convert_command(app, ctx);
  add_builtins_command(app, ctx);
  if (register_more) register_more(app, ctx);
  // `facetfit help [COMMAND]` is --help.
  if (argc >= 2 && std::string(argv[1]) == "help") {
    const CLI::App* sub = argc >= 3 ? find_command(app, argv[2]) : nullptr;
    if (argc >= 3 && !sub) {  // as `facetfit WORD` would say
      report_error(usage_error(app, argv[2], ""));
      return 2;
    }
    std::cout << (sub ? sub->help("facetfit") : app.help());
    return 0;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Help and --version exit 0; every usage error exits 2, as bin/commands.h promises, with one line in
    // the command's error style.
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
    report_error(usage_error(app, command_word(argc, argv), e.what()));
    return 2;
  } catch (const facetfit::Error& e) {
    report_error(e.what());
    return 1;
  } catch (const std::filesystem::filesystem_error& e) {
    // A path the system refuses (too long, a loop of links): the path and the system's reason, one line.
    report_error(excerpt(e.path1().string(), 200) + ": " + e.code().message());
    return 1;
  } catch (const std::exception& e) {
    report_error(std::string("internal: ") + e.what());
    return 1;
  }
  // Results go to standard output: a full disk or a closed file there must not pass for success.
  errno = 0;
  std::cout.flush();
  if (std::fflush(stdout) != 0 || std::ferror(stdout) || !std::cout) {
    report_error(std::string("cannot write to standard output") + (errno ? std::string(": ") + std::strerror(errno) : ""));
    return 1;
  }
  return ctx.status;
}

bool is_core_command(const std::string& name) { return name == "fit" || name == "convert" || name == "list-builtins"; }

}  // namespace facetfit::cli
