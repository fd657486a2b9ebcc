// facetfit bake INPUT... -o DIR : LUT textures and JSON sidecars for the pipeline, cached, in parallel.
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <thread>

#include "commands.h"
#include "core/error.h"
#include "io/atomic_file.h"
#include "io/folder_lock.h"
#include "io/input.h"
#include "lut/bake.h"
#include "lut/record.h"
#include "progress.h"
#include "render/scene.h"

namespace facetfit::cli {

namespace fs = std::filesystem;

namespace {

struct BakeArgs {
  std::vector<std::string> inputs;
  std::string out_dir;
  int jobs = 0;
  bool force = false;
  std::string scene;
  double tolerance = kDefaultTolerance;
  bool eval_only = false;
  FitSettings settings;
  ColorSettings color;
};

void report_outcome(Progress& progress, const BakeOutcome& o) {
  char line[512];
  std::snprintf(line, sizeof line, "%s %s (%.0f ms)", o.status == BakeOutcome::Status::cached ? "cached" : "baked ", o.name.c_str(),
                o.seconds * 1e3);
  // Implausible values are baked as measured, never silently: one warning line each.
  std::vector<std::string> warnings;
  if (o.status != BakeOutcome::Status::failed && o.record.contains("warnings"))
    for (const auto& w : o.record["warnings"]) warnings.push_back(o.source + ": " + w.get<std::string>());
  progress.step(o.name, line, o.status == BakeOutcome::Status::failed ? o.error : "", warnings);
}

std::string canonical(const std::string& source) {
  if (is_builtin(source)) return source;
  std::error_code ec;
  const fs::path p = fs::weakly_canonical(source, ec);
  return ec ? source : p.string();
}

// The inputs to bake: the expanded INPUTs, or with --scene only what the scene references: its list, or
// the inputs that are in it.
std::vector<std::string> select_inputs(const BakeArgs& args, const Context& ctx) {
  std::vector<std::string> inputs = expand_inputs(args.inputs);
  if (args.scene.empty()) return inputs;
  const std::vector<std::string> wanted = scene_materials(args.scene);
  if (inputs.empty()) return wanted;
  std::vector<std::string> kept;
  for (const auto& in : inputs)
    for (const auto& w : wanted)
      if (canonical(in) == canonical(w)) kept.push_back(in);
  if (!ctx.quiet()) std::fprintf(stderr, "facetfit: the scene references %zu of %zu inputs\n", kept.size(), inputs.size());
  return kept;
}

// Runs `step`; an Error it throws is reported, with status 1. Returns whether it succeeded.
template <class Step>
bool run_step(int& status, Step&& step) {
  try {
    step();
    return true;
  } catch (const Error& e) {
    report_error(e.what());
    status = 1;
    return false;
  }
}

// Output names must be unique: a second input with the same stem is an error, not an overwrite. Returns
// the indices of the inputs to bake; the others' outcomes hold the error.
std::vector<std::size_t> claim_output_names(const std::vector<std::string>& inputs, std::vector<BakeOutcome>& outcomes) {
  std::map<std::string, std::string> owner;
  std::vector<std::size_t> todo;
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    const std::string name = source_name(inputs[k]);
    const auto [it, fresh] = owner.emplace(name, inputs[k]);
    if (fresh) {
      todo.push_back(k);
    } else {
      outcomes[k].source = inputs[k];
      outcomes[k].name = name;
      outcomes[k].error = inputs[k] + ": output name " + name + " is already taken by " + it->second;
    }
  }
  return todo;
}

// The inputs at `todo`, baked `jobs` at a time (all cores for 0), each reported as it ends.
void bake_inputs(const std::vector<std::string>& inputs, const std::vector<std::size_t>& todo, const BakeArgs& args,
                 const BakeOptions& options, const Fitter& fitter, Progress& progress, std::vector<BakeOutcome>& outcomes) {
  const int jobs = args.jobs > 0 ? args.jobs : int(std::thread::hardware_concurrency());
  tbb::task_arena arena(std::max(1, jobs));
  arena.execute([&] {
    tbb::parallel_for(std::size_t(0), todo.size(), [&](std::size_t t) {
      const std::size_t k = todo[t];
      outcomes[k] = bake_material(inputs[k], source_name(inputs[k]), args.out_dir, options, fitter);
      report_outcome(progress, outcomes[k]);
    }, tbb::simple_partitioner());
  });
}

// Each baked or cached outcome's record as its sidecar is on disk now.
void reread_sidecars(const std::string& out_dir, std::vector<BakeOutcome>& outcomes) {
  for (auto& o : outcomes) {
    if (o.status == BakeOutcome::Status::failed) continue;
    nlohmann::json on_disk = read_json_file((fs::path(out_dir) / (o.name + ".json")).string());
    if (on_disk.is_object() && on_disk.contains("cache_key")) o.record = std::move(on_disk);
  }
}

// The index accumulates across batches: earlier entries stay while their LUT exists and this batch did
// not bake it again.
void keep_earlier_entries(const std::string& out_dir, const std::vector<BakeOutcome>& outcomes, nlohmann::json& materials) {
  std::set<std::string> luts_now;
  for (const auto& o : outcomes)
    if (o.status != BakeOutcome::Status::failed) luts_now.insert(o.record.value("lut", ""));
  const nlohmann::json previous = read_json_file((fs::path(out_dir) / "index.json").string());
  if (previous.is_object() && previous.contains("materials") && previous["materials"].is_array())
    for (const auto& m : previous["materials"]) {
      const std::string lut = m.is_object() ? m.value("lut", "") : "";
      std::error_code exists_error;
      if (!lut.empty() && !luts_now.count(lut) && fs::exists(fs::path(out_dir) / lut, exists_error)) materials.push_back(m);
    }
}

struct BakeCounts {
  int baked = 0, cached = 0, failed = 0;
};

// index.json's content: the earlier entries that stay, this batch's records, and this batch's failures.
BakeCounts make_index(const std::string& out_dir, const std::vector<BakeOutcome>& outcomes, nlohmann::json& index) {
  index["facetfit_version"] = FACETFIT_VERSION;
  index["materials"] = nlohmann::json::array();
  index["failures"] = nlohmann::json::array();
  keep_earlier_entries(out_dir, outcomes, index["materials"]);
  BakeCounts counts;
  for (const auto& o : outcomes) {
    if (o.status == BakeOutcome::Status::failed) {
      index["failures"].push_back({{"source", o.source}, {"error", o.error}});
      ++counts.failed;
    } else {
      index["materials"].push_back(o.record);
      (o.status == BakeOutcome::Status::cached ? counts.cached : counts.baked)++;
    }
  }
  return counts;
}

// The batch's counts, and each failure's error again at the end (status 1 when there is one); `index` is
// where index.json went, empty when it could not be written (that error already said why).
void report_summary(const BakeCounts& counts, const std::vector<BakeOutcome>& outcomes, const std::string& index, Context& ctx) {
  if (!ctx.quiet())
    std::printf("baked %d, cached %d, failed %d: %s\n", counts.baked, counts.cached, counts.failed,
                index.empty() ? "no index.json written" : index.c_str());
  if (counts.failed > 0) {
    std::fprintf(stderr, "facetfit: %d of %zu inputs failed:\n", counts.failed, outcomes.size());
    for (const auto& o : outcomes)
      if (o.status == BakeOutcome::Status::failed) std::fprintf(stderr, "  %s\n", o.error.c_str());
    ctx.status = 1;
  }
}

void run_bake(const BakeArgs& args, Context& ctx) {
  int& status = ctx.status;
  const auto fit = fit_options(args.settings, status);
  if (!fit) return;
  const std::vector<std::string> inputs = select_inputs(args, ctx);
  if (inputs.empty() && !args.scene.empty()) {  // a scene of LUTs and analytic materials needs no bake
    if (!ctx.quiet()) std::fprintf(stderr, "facetfit: %s references no measurement to bake\n", args.scene.c_str());
    return;
  }
  if (inputs.empty()) {
    report_error("no input (give files, folders, globs, builtin:NAME or builtin:, or --scene)");
    status = 2;
    return;
  }
  BakeOptions options;
  options.colorspace = args.color.working_space;
  if (!run_step(status, [&] { options.from_rec709 = args.color.from_rec709(args.color.config()); })) return;
  if (!run_step(status, [&] { prepare_output_folder(args.out_dir); })) return;

  options.fit = *fit;
  options.tolerance = args.tolerance;
  options.with_sampling = !args.eval_only;
  options.force = args.force;
  const Fitter fitter(options.fit);
  report_settings(ctx, "bake", options.fit);

  std::vector<BakeOutcome> outcomes(inputs.size());
  const std::vector<std::size_t> todo = claim_output_names(inputs, outcomes);
  Progress progress(inputs.size(), ctx.verbosity);
  for (const auto& o : outcomes)
    if (!o.error.empty()) report_outcome(progress, o);
  bake_inputs(inputs, todo, args, options, fitter, progress, outcomes);

  // index.json is read, merged and written under the folder's lock, from the sidecars as they are on disk:
  // a concurrent bake of the same names may have replaced them since, and the index must agree with them.
  // Whatever happens to it, the batch's summary follows.
  std::optional<FolderLock> lock;
  const std::string index_path = (fs::path(args.out_dir) / "index.json").string();
  bool indexed = run_step(status, [&] { lock.emplace(args.out_dir); });
  if (indexed) reread_sidecars(args.out_dir, outcomes);
  nlohmann::json index;
  const BakeCounts counts = make_index(args.out_dir, outcomes, index);
  indexed = indexed && run_step(status, [&] { write_file_atomic(index_path, json_text(index, 2) + "\n"); });
  report_summary(counts, outcomes, indexed ? index_path : "", ctx);
}

}  // namespace

void add_bake_command(CLI::App& app, Context& ctx) {
  auto args = std::make_shared<BakeArgs>();
  CLI::App* cmd = app.add_subcommand("bake", "Bake LUT textures (DIR/NAME.exr) and sidecars (DIR/NAME.json, DIR/index.json)");
  cmd->add_option("inputs", args->inputs, "Material files, folders, globs, builtin:NAME (builtin: for all)");
  cmd->add_option("-o,--output", args->out_dir, "Output folder (created if missing)")->required();
  cmd->add_option("-j,--jobs", args->jobs, "Materials baked at once (default: all cores)")->check(CLI::Range(1, 1024));
  cmd->add_flag("--force", args->force, "Bake even where the cache says the outputs are current");
  cmd->add_option("--scene", args->scene, "Bake only the materials this scene references");
  add_tolerance_option(cmd, args->tolerance);
  cmd->add_flag("--eval-only", args->eval_only, "Leave out the sampling tables");
  add_working_space_options(cmd, args->color);
  add_fit_settings(cmd, args->settings);
  cmd->callback([args, &ctx] { run_bake(*args, ctx); });
}

}  // namespace facetfit::cli
