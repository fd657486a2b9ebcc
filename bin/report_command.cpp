// facetfit report [DB] -o REPORT : the nightly database accuracy report, and `report merge` for shards.
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <filesystem>

#include "commands.h"
#include "core/error.h"
#include "farm_schedulers.h"
#include "io/input.h"
#include "lut/record.h"
#include "progress.h"
#include "report/report.h"

namespace facetfit::cli {

namespace {

namespace fs = std::filesystem;

constexpr int kMaxShards = 100000;

// "K/N", the whole text, 1 <= K <= N <= kMaxShards: digits only, so no sign, space or overflow gets through.
bool parse_shard(const std::string& text, int& k, int& n) {
  const std::size_t slash = text.find('/');
  if (slash == std::string::npos) return false;
  const auto number = [](const char* begin, const char* end, int& value) {
    if (begin == end || end - begin > 6) return false;
    const auto [p, ec] = std::from_chars(begin, end, value);
    return ec == std::errc() && p == end && *begin != '-' && *begin != '+';
  };
  const char* s = text.data();
  return number(s, s + slash, k) && number(s + slash + 1, s + text.size(), n) && k >= 1 && n >= k && n <= kMaxShards;
}

struct ReportArgs {
  std::vector<std::string> inputs;
  std::string out_dir, luts_dir;
  int size = ReportOptions{}.size, spp = ReportOptions{}.spp;
  std::string shard = "1/1";
  bool fail_on_regression = false;
  bool accept = false;
  bool force = false;
  double tolerance = kDefaultTolerance;
  std::uint64_t max_memory = 0;
  FitSettings settings;
  ColorSettings color;  // the pictures' --display and --view
  // --farm local|slurm: the report as a plan of shards (report/farm.h) run by an adapter (bin/farm_schedulers.h).
  std::string farm;
  int shards = 4;
  bool wait = false, dry_run = false;
  SlurmSettings slurm;
};

// A number as an argument that reads back as the same double (std::to_string keeps 6 decimals).
std::string exact(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", x);
  return text;
}

// The settings every shard of a farm passes on, as arguments of `report`.
std::vector<std::string> shard_settings(const ReportArgs& a) {
  std::vector<std::string> s = {"--size", std::to_string(a.size), "--spp", std::to_string(a.spp), "--tolerance", exact(a.tolerance),
                                "--smith", a.settings.smith, "--resolution", std::to_string(a.settings.resolution),
                                "--refine", a.settings.refine, "--merl-bins", a.settings.merl_bins,
                                "--closure-fresnel", a.settings.closure_fresnel,
                                "--max-iterations", std::to_string(a.settings.max_iterations),
                                "--iteration-tolerance", exact(a.settings.iteration_tolerance)};
  if (a.max_memory > 0) s.insert(s.end(), {"--max-memory", std::to_string(a.max_memory)});
  if (a.force) s.push_back("--force");
  for (const auto& [flag, value] : {std::pair{"--display", &a.color.display}, {"--view", &a.color.view}, {"--ocio-config", &a.color.ocio_config}})
    if (!value->empty()) s.insert(s.end(), {flag, *value});
  return s;
}

void run_farm_command(const ReportArgs& args, Context& ctx) {
  if (!fit_options(args.settings, ctx.status)) return;
  if (args.shard != "1/1") {
    report_error("report: --farm splits the database itself; it takes no --shard");
    ctx.status = 2;
    return;
  }
  std::vector<std::string> sources = expand_inputs(args.inputs.empty() ? std::vector<std::string>{kBuiltinPrefix} : args.inputs);
  // What the shards could not read is refused here, once, before anything is submitted.
  for (const std::string& source : sources) {
    std::error_code ec;
    if (!is_builtin(source) && !fs::is_regular_file(source, ec)) {
      report_error(source + ": no such material file (nothing submitted, " + args.out_dir + " not published)");
      ctx.status = 1;
      return;
    }
  }
  std::sort(sources.begin(), sources.end());
  const std::string out_dir = fs::absolute(args.out_dir).lexically_normal().string();
  std::vector<std::string> absolute;
  for (const std::string& s : sources) absolute.push_back(is_builtin(s) ? s : fs::absolute(s).lexically_normal().string());
  const std::string luts_dir = args.luts_dir.empty() ? "" : fs::absolute(args.luts_dir).lexically_normal().string();
  std::vector<std::string> merge_flags;
  if (args.fail_on_regression) merge_flags.push_back("--fail-on-regression");
  if (args.accept) merge_flags.push_back("--accept");
  const FarmPlan plan = plan_report_farm(absolute, args.shards, out_dir, luts_dir, shard_settings(args), merge_flags);
  if (args.dry_run) {
    if (args.farm == "slurm") {
      std::printf("# %s/.farm/shards.sbatch: sbatch --array=1-%zu shards.sbatch\n%s\n", out_dir.c_str(), plan.shards.size(),
                  slurm_array_script(plan, args.slurm).c_str());
      std::printf("# %s/.farm/merge.sbatch: sbatch --dependency=afterok:ARRAY_JOB_ID merge.sbatch\n%s", out_dir.c_str(),
                  slurm_merge_script(plan, args.slurm).c_str());
    } else {
      std::printf("%s\n", json_text(plan.to_json(), 2).c_str());
    }
    return;
  }
  try {
    ctx.status = args.farm == "slurm" ? run_farm_slurm(plan, args.slurm, args.wait, ctx) : run_farm_local(plan, ctx);
  } catch (const Error& e) {
    report_error(e.what());
    ctx.status = 1;
  }
  if (ctx.status == 0 || ctx.status == 3)
    if (!ctx.quiet() && (args.farm == "local" || args.wait)) std::printf("%s/index.html\n", out_dir.c_str());
}

void finish(const nlohmann::json& report, const std::string& out_dir, bool fail_on_regression, Context& ctx) {
  if (!ctx.quiet()) std::printf("%s/index.html\n", out_dir.c_str());
  for (const auto& [r, v] : report["database_mean_delta_e"].items())
    if (!ctx.quiet()) std::printf("  mean Delta E 2000 %-10s %s\n", r.c_str(), v.is_null() ? "-" : std::to_string(v.get<double>()).c_str());
  for (const auto& f : report["failures"]) report_error(f["error"].get<std::string>());
  const bool accepted = report.value("accepted", false);
  for (const auto& g : report["regressions"])
    std::fprintf(stderr, "facetfit: regression%s: %s %s %.4f -> %.4f (%s)\n", accepted ? " (accepted)" : "", g["name"].get<std::string>().c_str(),
                 g["representation"].get<std::string>().c_str(), g["before"].get<double>(), g["after"].get<double>(),
                 g.value("cause", std::string()).c_str());
  for (const auto& name : report.value("removed", nlohmann::json::array()))
    std::fprintf(stderr, "facetfit: removed: %s is in the baseline but not in this report (--accept drops it)\n", name.get<std::string>().c_str());
  const bool regressed = !report["regressions"].empty() || !report.value("removed", nlohmann::json::array()).empty();
  if (!report["failures"].empty())
    ctx.status = 1;
  else if (fail_on_regression && regressed && !accepted)
    ctx.status = 3;
}

void run_report_command(const ReportArgs& args, Context& ctx) {
  int& status = ctx.status;
  const auto fit = fit_options(args.settings, status);
  if (!fit) return;
  ReportOptions o;
  o.inputs = args.inputs;
  o.out_dir = args.out_dir;
  o.luts_dir = args.luts_dir;
  o.size = args.size;
  o.spp = args.spp;
  o.max_memory = args.max_memory;
  o.force = args.force;
  o.accept = args.accept;
  o.bake.fit = *fit;
  o.bake.tolerance = args.tolerance;
  if (!args.color.display.empty() || !args.color.view.empty()) {
    try {
      o.pictures = std::make_shared<const DisplayTransform>(args.color.pictures(args.color.config(), kRec709Space, ColorMatrix(1.0)));
    } catch (const Error& e) {
      report_error(e.what());
      status = 1;
      return;
    }
    o.pictures_name = "display " + args.color.display + ", view " + (args.color.view.empty() ? "(its default)" : args.color.view);
  }
  if (!parse_shard(args.shard, o.shard, o.shards)) {
    report_error("--shard " + excerpt(args.shard, 40) + ": must be K/N with 1 <= K <= N <= " + std::to_string(kMaxShards));
    status = 2;
    return;
  }
  if (o.size < 8 || o.size > 4096 || o.spp < 1 || o.spp > (1 << 20)) {
    report_error("--size must be in [8, 4096] and --spp in [1, 1048576]");
    status = 2;
    return;
  }
  report_settings(ctx, "report", o.bake.fit);
  std::shared_ptr<Progress> progress;
  o.progress = [&progress, &ctx](const std::string& name, const std::string& what, std::size_t done, std::size_t total) {
    if (!progress) progress = std::make_shared<Progress>(total, ctx.verbosity);
    progress->step(name, "report: " + std::to_string(done) + "/" + std::to_string(total) + " " + name + " (" + what + ")");
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
  cmd->add_option("--luts", args->luts_dir, "Bake cache folder (default REPORT/luts; the shards of a farm share one)");
  cmd->add_option("--size", args->size, "Image side in pixels")->capture_default_str();
  cmd->add_option("--spp", args->spp, "Samples per pixel")->capture_default_str();
  add_view_options(cmd, args->color);
  add_max_memory_option(cmd, args->max_memory);
  cmd->add_option("--shard", args->shard, "K/N: render the K-th of N deterministic subsets (merge them with report merge)")
      ->capture_default_str();
  cmd->add_flag("--fail-on-regression", args->fail_on_regression,
                "Exit 3 when a material got worse than its baseline (the last accepted figures) or left the database");
  cmd->add_flag("--accept", args->accept, "This run's figures become the baseline, regressions and removed materials included");
  cmd->add_flag("--force", args->force, "Render even the materials whose previous entry is current");
  add_tolerance_option(cmd, args->tolerance);
  add_fit_settings(cmd, args->settings);
  cmd->add_option("--farm", args->farm, "Split the report into shards run by: local (processes on this machine) or slurm (a job array and a merge job)")
      ->check(CLI::IsMember({"local", "slurm"}));
  cmd->add_option("--shards", args->shards, "--farm: number of shards, balanced by the previous report's timings")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  cmd->add_option("--partition", args->slurm.partition, "--farm slurm: sbatch --partition");
  cmd->add_option("--time", args->slurm.time, "--farm slurm: sbatch --time of each shard");
  cmd->add_option("--mem", args->slurm.mem, "--farm slurm: sbatch --mem of each shard");
  cmd->add_option("--sbatch-arg", args->slurm.extra, "--farm slurm: a further sbatch option (repeatable)");
  cmd->add_flag("--wait", args->wait, "--farm slurm: wait for the shards (resubmitting a failed one once) and the merge; exit with the merge's status");
  cmd->add_flag("--dry-run", args->dry_run, "--farm: print the plan (slurm: the two sbatch scripts) and submit nothing");

  auto parts = std::make_shared<std::vector<std::string>>();
  auto merged = std::make_shared<std::string>();
  auto fail_merge = std::make_shared<bool>(false), accept_merge = std::make_shared<bool>(false);
  CLI::App* merge = cmd->add_subcommand("merge", "Join shard reports into one");
  merge->add_option("parts", *parts, "Report folders written with --shard")->required();
  merge->add_option("-o,--output", *merged, "Merged report folder")->required();
  merge->add_flag("--fail-on-regression", *fail_merge, "Exit 3 on regressions against the merged folder's baseline");
  merge->add_flag("--accept", *accept_merge, "This merge's figures become the baseline");
  merge->callback([parts, merged, fail_merge, accept_merge, &ctx] {
    try {
      finish(merge_reports(*parts, *merged, *accept_merge), *merged, *fail_merge, ctx);
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
    if (!args->farm.empty()) run_farm_command(*args, ctx);
    else run_report_command(*args, ctx);
  });
}

}  // namespace facetfit::cli
