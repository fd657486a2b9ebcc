// facetfit fit INPUT... : NDF, Fresnel and roughness of each material, as a table or JSON lines.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "core/error.h"
#include "fit/fit.h"
#include "io/input.h"
#include "lut/record.h"

namespace facetfit::cli {

namespace {

struct FitArgs {
  std::vector<std::string> inputs;
  bool builtin = false;
  FitSettings settings;
  bool json = false;
};

void print_row(const std::string& source, const FitResult& r, double seconds) {
  if (!r.ok()) {
    std::printf("%-28s  %-s\n", source.c_str(), ("no fit: " + r.problem).c_str());
    return;
  }
  std::printf("%-28s  %9.4f  %9.4f  %5.3f %5.3f %5.3f  %5.3f %5.3f %5.3f  %5d  %8.1e  %7.1f\n", source.c_str(), r.alpha_ggx,
              r.alpha_beckmann, r.f0.r, r.f0.g, r.f0.b, r.f82.r, r.f82.g, r.f82.b, r.extraction.iterations,
              r.extraction.residual, seconds * 1e3);
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

  if (!args.json)
    std::printf("%-28s  %9s  %9s  %-17s  %-17s  %5s  %8s  %7s\n", "material", "alpha_ggx", "alpha_bkm", "f0 (r g b)",
                "f82 (r g b)", "iters", "residual", "ms");
  int failures = 0;
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
      if (args.json)
        std::printf("%s\n", json_text(fit_record(source, result, seconds)).c_str());
      else
        print_row(source_name(source), result, seconds);
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
  cmd->add_flag("--json", args->json, "One JSON object per material on stdout");
  cmd->callback([args, &ctx] { run_fit(*args, ctx); });
}

}  // namespace facetfit::cli
