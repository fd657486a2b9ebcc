// facetfit report [DB] -o REPORT : the nightly database accuracy report, and `report merge` for shards.
#include <unistd.h>

#include <cstdio>

#include "commands.h"
#include "core/error.h"
#include "progress.h"
#include "report/report.h"

namespace facetfit::cli {

namespace {

struct ReportArgs {
  std::vector<std::string> inputs;
  std::string out_dir;
  int size = 128, spp = 32;
  std::string shard = "1/1";
  bool fail_on_regression = false;
  bool force = false;
  double tolerance = 0.02;
  std::uint64_t max_memory = 0;
  FitSettings settings;
};

void finish(const nlohmann::json& report, const std::string& out_dir, bool fail_on_regression, Context& ctx) {
  if (!ctx.quiet()) std::printf("%s/index.html\n", out_dir.c_str());
  for (const auto& [r, v] : report["database_mean_delta_e"].items())
    if (!ctx.quiet()) std::printf("  mean Delta E 2000 %-10s %s\n", r.c_str(), v.is_null() ? "-" : std::to_string(v.get<double>()).c_str());
  for (const auto& f : report["failures"]) report_error(f["error"].get<std::string>());
  for (const auto& g : report["regressions"])
    std::fprintf(stderr, "facetfit: regression: %s %s %.4f -> %.4f\n", g["name"].get<std::string>().c_str(),
                 g["representation"].get<std::string>().c_str(), g["before"].get<double>(), g["after"].get<double>());
  if (!report["failures"].empty())
    ctx.status = 1;
  else if (fail_on_regression && !report["regressions"].empty())
    ctx.status = 3;
}

void run_report_command(const ReportArgs& args, Context& ctx) {
  int& status = ctx.status;
  const auto fit = fit_options(args.settings, status);
  if (!fit) return;
  ReportOptions o;
  o.inputs = args.inputs;
  o.out_dir = args.out_dir;
  o.size = args.size;
  o.spp = args.spp;
  o.max_memory = args.max_memory;
  o.force = args.force;
  o.bake.fit = *fit;
  o.bake.tolerance = args.tolerance;
  if (std::sscanf(args.shard.c_str(), "%d/%d", &o.shard, &o.shards) != 2 || o.shards < 1 || o.shard < 1 || o.shard > o.shards) {
    report_error("--shard " + args.shard + ": must be K/N with 1 <= K <= N");
    status = 2;
    return;
  }
  if (o.size < 8 || o.size > 4096 || o.spp < 1) {
    report_error("--size must be in [8, 4096] and --spp at least 1");
    status = 2;
    return;
  }
  report_settings(ctx, "report", o.bake.fit);
  std::shared_ptr<Progress> progress;
  o.progress = [&progress, &ctx](const std::string& name, std::size_t done, std::size_t total) {
    if (!progress) progress = std::make_shared<Progress>(total, ctx.verbosity);
    progress->step(name, "report: " + std::to_string(done) + "/" + std::to_string(total) + " " + name);
  };
  try {
    finish(run_report(o), o.out_dir, args.fail_on_regression, ctx);
  } catch (const Error& e) {
    report_error(e.what());
    status = 1;
  }
}

}  // namespace

void add_report_command(CLI::App& app, Context& ctx) {
  auto args = std::make_shared<ReportArgs>();
  CLI::App* cmd = app.add_subcommand("report", "The database accuracy report: measured vs tabulated vs GGX vs Beckmann, mean Delta E 2000");
  cmd->add_option("db", args->inputs, "Material files, folders, globs (default: the built-in set, builtin:)");
  cmd->add_option("-o,--output", args->out_dir, "Report folder (report.json, index.html, images/, luts/)");
  cmd->add_option("--size", args->size, "Image side in pixels")->capture_default_str();
  cmd->add_option("--spp", args->spp, "Samples per pixel")->capture_default_str();
  add_max_memory_option(cmd, args->max_memory);
  cmd->add_option("--shard", args->shard, "K/N: render the K-th of N deterministic subsets (merge them with report merge)")
      ->capture_default_str();
  cmd->add_flag("--fail-on-regression", args->fail_on_regression, "Exit 3 when a material got worse than in the previous report");
  cmd->add_flag("--force", args->force, "Render even the materials whose previous entry is current");
  cmd->add_option("--tolerance", args->tolerance, "Representation tolerance of the bake")->capture_default_str();
  add_fit_settings(cmd, args->settings);

  auto parts = std::make_shared<std::vector<std::string>>();
  auto merged = std::make_shared<std::string>();
  auto fail_merge = std::make_shared<bool>(false);
  CLI::App* merge = cmd->add_subcommand("merge", "Join shard reports into one");
  merge->add_option("parts", *parts, "Report folders written with --shard")->required();
  merge->add_option("-o,--output", *merged, "Merged report folder")->required();
  merge->add_flag("--fail-on-regression", *fail_merge, "Exit 3 on regressions against the previous merged report");
  merge->callback([parts, merged, fail_merge, &ctx] {
    try {
      finish(merge_reports(*parts, *merged), *merged, *fail_merge, ctx);
    } catch (const Error& e) {
      report_error(e.what());
      ctx.status = 1;
    }
  });
  cmd->callback([cmd, merge, args, &ctx] {
    if (merge->parsed()) return;
    if (args->out_dir.empty()) {
      report_error("report: -o REPORT is required");
      ctx.status = 2;
      return;
    }
    run_report_command(*args, ctx);
  });
}

}  // namespace facetfit::cli
