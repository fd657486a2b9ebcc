// The nightly database accuracy report: every material of a database rendered from its measurement and
// from each fitted representation, compared by mean CIE Delta E 2000 on the display-referred images.
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "color/display.h"
#include "lut/bake.h"

namespace facetfit {

struct ReportOptions {
  std::vector<std::string> inputs;  // files, folders, globs, builtin:...
  std::string out_dir;
  std::string luts_dir;  // the bake cache; empty: out_dir/luts (shards of a farm share one)
  int size = 128;   // image side, pixels
  // Samples per pixel. Noise adds to Delta E: on the built-in set, against 1024 spp, 32 spp added a mean of
  // 0.22 (at most 1.85), 256 adds 0.034 (at most 0.39), less than the gaps between the database means it
  // ranks (docs/report-noise.md, bench/report_noise.py).
  int spp = 256;
  std::uint64_t max_memory = 0;  // per render (render/renderer.h); 0: half of the machine's
  int shard = 1, shards = 1;  // this run renders materials k with k % shards == shard - 1
  bool force = false;
  bool accept = false;  // this run's figures become the baseline, regressions and removed materials included
  BakeOptions bake;
  // The pictures' display and view (a studio's, color/display.h) and its name; null: the sRGB display,
  // through which Delta E is measured whatever the pictures show.
  std::shared_ptr<const DisplayTransform> pictures;
  std::string pictures_name;
  // Called after each material: its name, what was done ("rendered", "reused" from the previous run, "failed").
  std::function<void(const std::string& name, const std::string& what, std::size_t done, std::size_t total)> progress;
};

// The representations compared with the measurement, in report order.
const std::vector<std::string>& report_representations();

// Runs the report into options.out_dir (report.json, index.html, images/, luts/), reusing the previous
// report's entries whose inputs, settings and version are unchanged. Returns report.json's content.
// Materials that fail are listed under "failures"; the run goes on.
nlohmann::json run_report(const ReportOptions& options);

// Joins shard reports (their report.json folders) into one, copying their images; judged against the
// merged folder's previous baseline.
nlohmann::json merge_reports(const std::vector<std::string>& parts, const std::string& out_dir, bool accept = false);

// The figures a report is judged against (report.json's "baseline": per material its Delta E, the input's
// SHA-256 and the facetfit version): the previous report's baseline, or for a report written before
// baselines, its own figures.
nlohmann::json baseline_of(const nlohmann::json& previous);

// Materials whose Delta E rose against baseline_of(previous) (same name and representation): by more than
// 10% and more than 0.1. Each entry: {name, representation, before, after, cause}, the cause whether the
// input file, facetfit, both or neither changed since the baseline.
nlohmann::json find_regressions(const nlohmann::json& previous, const nlohmann::json& current);

// Sets report's "regressions", "removed" (baseline materials absent from it), "accepted" and the next
// "baseline": a regressed material keeps its baseline figures, so a failed nightly run again fails again,
// and a removed one stays listed, until a run with `accept` takes this run's figures as they are.
void judge_against_baseline(const nlohmann::json& previous, nlohmann::json& report, bool accept);

}  // namespace facetfit
