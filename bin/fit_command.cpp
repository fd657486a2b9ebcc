// facetfit fit INPUT... : each material's recommended representation and its own parameters (fit/recommend.h),
// with the paper's moment alphas beside them, as a table or JSON lines (the whole record).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "core/error.h"
#include "fit/fit.h"
#include "io/input.h"
#include "fit/recommend.h"
#include "lut/record.h"

namespace facetfit::cli {

namespace {

struct FitArgs {
  std::vector<std::string> inputs;
  bool builtin = false;
  FitSettings settings;
  double tolerance = kDefaultTolerance;
  bool json = false;
};

void print_header() {
  std::printf("%-28s  %-11s  %7s  %-17s  %-17s  %-17s  %8s  %15s  %7s\n", "material", "recommended", "alpha", "f0 (r g b)",
              "f82 (r g b)", "body (r g b)", "distance", "moment alpha", "ms");
  std::printf("%-28s  %-11s  %7s  %-17s  %-17s  %-17s  %8s  %7s %7s  %7s\n", "", "", "", "", "", "", "", "ggx", "bkm", "");
}

// The recommended representation's own parameters; the moment alphas are the paper's estimates of the
// tabulated NDF, not a representation (the ggx fit's alpha differs).
void print_row(const std::string& source, const FitResult& r, double tolerance, double seconds) {
  if (!r.ok()) {
    std::printf("%-28s  %-s\n", source.c_str(), ("no fit: " + r.problem).c_str());
    return;
  }
  const RepresentationParameters p = parameters_of(r, recommend(r, tolerance));
  char alpha[16] = "table";  // the tabulated NDF has no alpha, the closures one per lobe
  if (p.alpha) std::snprintf(alpha, sizeof alpha, "%.4f", *p.alpha);
  if (p.representation == Representation::closures) std::snprintf(alpha, sizeof alpha, "%zu lobe%s", r.closures.closures.lobes.size(),
                                                                  r.closures.closures.lobes.size() > 1 ? "s" : "");
  std::printf("%-28s  %-11s  %7s  %5.3f %5.3f %5.3f  %5.3f %5.3f %5.3f  %5.3f %5.3f %5.3f  %8.4f  %7.4f %7.4f  %7.1f\n",
              source.c_str(), to_string(p.representation), alpha, p.f0.r, p.f0.g, p.f0.b, p.f82.r, p.f82.g, p.f82.b,
              p.body.r, p.body.g, p.body.b, p.error, r.alpha_ggx, r.alpha_beckmann, seconds * 1e3);
  if (p.coat.present()) std::printf("%-28s  coat: GGX alpha %.4f, f0 %.4f\n", "", p.coat.alpha, p.coat.f0);
  if (const auto& a = r.anisotropic)
    std::printf("%-28s  anisotropic: ggx %.4f x %.4f, beckmann %.4f x %.4f, x axis at %.1f degrees (the row above: the azimuthal mean)\n", "",
                a->ggx.alpha.alpha_x, a->ggx.alpha.alpha_y, a->beckmann.alpha.alpha_x, a->beckmann.alpha.alpha_y,
                a->ggx.alpha.angle * 180.0 / kPi);
}

void run_fit(const FitArgs& args, Context& ctx) {
  int& status = ctx.status;
  const auto options = fit_options(args.settings, status);
  if (!options) return;
  std::vector<std::string> raw = args.inputs;
  if (args.builtin) raw.push_back(kBuiltinPrefix);
  const std::vector<std::string> inputs = expand_inputs(raw);
  if (inputs.empty()) {
    report_error("no input (give files, folders, builtin:NAME, or --builtin)");
    status = 2;
    return;
  }
  const Fitter fitter(*options);
  report_settings(ctx, "fit", *options);

  int failures = 0;
  bool header = false;  // printed before the first fit, so that a run whose inputs all fail prints none
  for (const std::string& source : inputs) {
    try {
      const auto start = std::chrono::steady_clock::now();
      const FitResult result = fitter.fit(load_table(source, fitter.options().merl_bins));
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (!result.ok()) {
        report_error(source + ": meaningless fit: " + result.problem);
        ++failures;
      }
      for (const std::string& w : result.warnings) std::fprintf(stderr, "facetfit: warning: %s: %s\n", source.c_str(), w.c_str());
      if (args.json) {
        std::printf("%s\n", json_text(fit_record(source, result, seconds, args.tolerance)).c_str());
      } else {
        if (!header) print_header(), header = true;
        print_row(source_name(source), result, args.tolerance, seconds);
      }
      std::fflush(stdout);
    } catch (const Error& e) {
      report_error(e.what());
      ++failures;
    }
  }
  if (failures > 0) {
    std::fprintf(stderr, "facetfit: %d of %zu inputs failed\n", failures, inputs.size());
    status = 1;
  }
}

}  // namespace

void add_fit_command(CLI::App& app, Context& ctx) {
  auto args = std::make_shared<FitArgs>();
  CLI::App* cmd = app.add_subcommand("fit", "Fit microfacet components to measured materials");
  cmd->add_option("inputs", args->inputs, "MERL .binary, RGL .bsdf or UTIA .bin files, folders of them, or builtin:NAME (builtin: for all)");
  cmd->add_flag("--builtin", args->builtin, "Fit every built-in synthetic material");
  add_fit_settings(cmd, args->settings);
  add_tolerance_option(cmd, args->tolerance);
  cmd->add_flag("--json", args->json, "One JSON object per material on stdout");
  cmd->callback([args, &ctx] { run_fit(*args, ctx); });
}

}  // namespace facetfit::cli
