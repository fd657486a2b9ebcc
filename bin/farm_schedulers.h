// The scheduler adapters of `report --farm` (bin/farm_schedulers.cpp): they run or submit a plan (report/farm.h).
#pragma once

#include <string>
#include <vector>

#include "commands.h"
#include "report/farm.h"

namespace facetfit::cli {

struct SlurmSettings {
  std::string partition, time, mem;  // sbatch --partition, --time, --mem (empty: the site's defaults)
  std::vector<std::string> extra;    // further sbatch options, one per --sbatch-arg
};

// Every shard as a process of this executable at once (logs in parts_dir/K.log), a failed shard once
// more, then the merge; nothing is published unless every shard succeeded. Returns the exit status.
int run_farm_local(const FarmPlan& plan, const Context& ctx);

// The batch scripts: the shards' job array (a failed shard runs once more inside its task and marks its
// success) and the merge, which refuses to publish unless every shard marked success.
std::string slurm_array_script(const FarmPlan& plan, const SlurmSettings& settings);
std::string slurm_merge_script(const FarmPlan& plan, const SlurmSettings& settings);

// Submits the array and the merge (sbatch --dependency=afterok) and prints the job ids; with `wait`,
// waits, submits the shards that did not finish once more, then the merge, and returns its status.
int run_farm_slurm(const FarmPlan& plan, const SlurmSettings& settings, bool wait, const Context& ctx);

}  // namespace facetfit::cli
