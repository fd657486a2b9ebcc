// The nightly report split over a cluster: which materials each shard renders, balanced by the previous
// report's timings and deterministic, each shard's command and the merge's. A plan is data: the
// scheduler adapters of the command (bin/farm_schedulers.cpp: local processes, Slurm) run or submit it, and print it.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace facetfit {

// Splits weighted items over `shards` bins, longest first onto the least loaded bin (ties: the name, then
// the lower bin): the largest bin is at most 4/3 of the best split's (Graham's bound). Empty bins are
// dropped; each bin keeps its items sorted by name.
std::vector<std::vector<std::string>> balance_shards(std::vector<std::pair<std::string, double>> costs, int shards);

// Seconds each material took in a previous report.json (bake and every render), by source; materials it
// does not hold get the median of those it does (1 when it holds none).
std::vector<std::pair<std::string, double>> material_costs(const std::vector<std::string>& sources, const nlohmann::json& previous);

struct FarmPlan {
  std::string out_dir;    // where the merged report goes
  std::string parts_dir;  // out_dir/.farm: part K in parts_dir/K, logs beside them
  std::string luts_dir;   // the bake cache all shards share (out_dir/luts unless given)
  std::vector<std::vector<std::string>> shards;       // the sources of each shard
  std::vector<std::vector<std::string>> commands;     // each shard's facetfit arguments (no executable)
  std::vector<std::string> merge;                     // the merge's facetfit arguments
  std::string part(std::size_t k) const;              // parts_dir/(k + 1)
  nlohmann::json to_json() const;
};

// The plan of `report` over `shards` shards: sources already expanded; `luts_dir` the shared bake cache
// (empty: out_dir/luts); `report_args` are the settings every shard passes on (--size, --spp, fit
// settings ...), `merge_args` the merge's (--fail-on-regression).
FarmPlan plan_report_farm(const std::vector<std::string>& sources, int shards, const std::string& out_dir, const std::string& luts_dir,
                          const std::vector<std::string>& report_args, const std::vector<std::string>& merge_args);

}  // namespace facetfit
