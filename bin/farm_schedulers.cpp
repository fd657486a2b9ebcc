// The scheduler adapters of `report --farm`: a plan (report/farm.h) run as local processes, or submitted to
// Slurm as one job array and a merge job. Both retry a failed shard once and publish the merged report
// only when every shard succeeded.
#include "farm_schedulers.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "core/error.h"
#include "io/atomic_file.h"
#include "io/input.h"

extern char** environ;

namespace facetfit::cli {

namespace fs = std::filesystem;

namespace {

std::string self_executable() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? "facetfit" : exe.string();
}

// A word for /bin/sh: single-quoted, quotes inside closed and escaped.
std::string quote(const std::string& word) {
  std::string out = "'";
  for (char c : word) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string command_line(const std::vector<std::string>& args) {
  std::string line = quote(self_executable());
  for (const std::string& a : args) line += " " + quote(a);
  return line;
}

std::string shard_names(const FarmPlan& plan, std::size_t k) {
  std::string names;
  for (const std::string& s : plan.shards[k]) names += (names.empty() ? "" : " ") + source_name(s);
  return names;
}

// Starts this executable with `args`, its output into `log`. Returns the pid, or -1.
pid_t spawn(const std::vector<std::string>& args, const std::string& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  const std::string exe = self_executable();
  std::vector<std::string> words = {exe, "-q"};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  if (::posix_spawn(&pid, exe.c_str(), &actions, nullptr, argv.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&actions);
  return pid;
}

// Runs a shell command, returning its exit status and standard output.
int run_shell(const std::string& command, std::string* output) {
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return -1;
  char buffer[4096];
  std::string out;
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.append(buffer, n);
  const int status = ::pclose(pipe);
  if (output) *output = out;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The exit status of a spawned process (spawn's pid), or -1 when it did not start or did not exit.
int exit_status(pid_t pid) {
  int status = 0;
  if (pid < 0 || ::waitpid(pid, &status, 0) != pid || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

std::string done_marker(const FarmPlan& plan, std::size_t k) { return plan.part(k) + ".done"; }

}  // namespace

int run_farm_local(const FarmPlan& plan, const Context& ctx) {
  fs::create_directories(plan.parts_dir);
  std::vector<std::size_t> todo(plan.shards.size());
  for (std::size_t k = 0; k < todo.size(); ++k) todo[k] = k;
  for (int attempt = 0; attempt < 2 && !todo.empty(); ++attempt) {
    std::vector<std::pair<std::size_t, pid_t>> running;
    for (std::size_t k : todo) running.emplace_back(k, spawn(plan.commands[k], plan.part(k) + ".log"));
    std::vector<std::size_t> failed;
    for (const auto& [k, pid] : running) {
      if (exit_status(pid) != 0) {
        failed.push_back(k);
        if (!ctx.quiet() || attempt == 1)
          std::fprintf(stderr, "facetfit: %s: shard %zu (%s) failed%s; its log: %s.log\n", attempt == 0 ? "warning" : "error", k + 1,
                       shard_names(plan, k).c_str(), attempt == 0 ? ", running it again" : "", plan.part(k).c_str());
      }
    }
    todo = failed;
  }
  if (!todo.empty()) {
    report_error(plan.out_dir + ": not published: " + std::to_string(todo.size()) + " of " + std::to_string(plan.shards.size()) +
                 " shards failed twice");
    return 1;
  }
  const int status = exit_status(spawn(plan.merge, plan.parts_dir + "/merge.log"));
  if (status != 0 && status != 3) {
    report_error(plan.out_dir + ": merge failed; its log: " + plan.parts_dir + "/merge.log");
    return 1;
  }
  return status;
}

std::string slurm_array_script(const FarmPlan& plan, const SlurmSettings& s) {
  std::ostringstream out;
  out << "#!/bin/sh\n#SBATCH --job-name=facetfit-report\n#SBATCH --output=" << plan.parts_dir << "/%a.log\n";
  if (!s.partition.empty()) out << "#SBATCH --partition=" << s.partition << "\n";
  if (!s.time.empty()) out << "#SBATCH --time=" << s.time << "\n";
  if (!s.mem.empty()) out << "#SBATCH --mem=" << s.mem << "\n";
  for (const std::string& a : s.extra) out << "#SBATCH " << a << "\n";
  out << "# One task per shard (sbatch --array=1-" << plan.shards.size() << "); a failed shard runs once more, and marks\n"
      << "# its success for the merge.\ncase \"$SLURM_ARRAY_TASK_ID\" in\n";
  for (std::size_t k = 0; k < plan.commands.size(); ++k) {
    const std::string run = command_line(plan.commands[k]);
    out << "  " << k + 1 << ") (" << run << " || " << run << ") && touch " << quote(done_marker(plan, k)) << " ;;\n";
  }
  out << "  *) echo \"facetfit: no shard $SLURM_ARRAY_TASK_ID\" >&2; exit 2 ;;\nesac\n";
  return out.str();
}

std::string slurm_merge_script(const FarmPlan& plan, const SlurmSettings& s) {
  std::ostringstream out;
  out << "#!/bin/sh\n#SBATCH --job-name=facetfit-merge\n#SBATCH --output=" << plan.parts_dir << "/merge.log\n";
  if (!s.partition.empty()) out << "#SBATCH --partition=" << s.partition << "\n";
  for (const std::string& a : s.extra) out << "#SBATCH " << a << "\n";
  out << "# Submitted with --dependency=afterok on the shards: runs only when every shard succeeded.\n";
  std::string check;
  for (std::size_t k = 0; k < plan.shards.size(); ++k) check += " && test -f " + quote(done_marker(plan, k));
  out << "true" << check << " || { echo 'facetfit: error: a shard did not finish; not published' >&2; exit 1; }\n";
  out << command_line(plan.merge) << "\nstatus=$?\necho $status > " << quote(plan.parts_dir + "/merge.status") << "\nexit $status\n";
  return out.str();
}

namespace {

// sbatch SCRIPT with `options`; the job id, or an Error naming what sbatch said.
std::string submit(const std::string& script_path, const std::string& options) {
  std::string out;
  const int status = run_shell("sbatch --parsable " + options + " " + quote(script_path) + " 2>&1", &out);
  const std::string id = out.substr(0, out.find_first_of(";\n"));
  if (status != 0 || id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
    throw Error("sbatch: " + out.substr(0, out.find('\n')));
  return id;
}

// Until squeue no longer lists the job (or no longer knows it). A controller that cannot be reached for
// a minute is an error, not a reason to wait forever.
void wait_for(const std::string& job) {
  int unreachable = 0;
  for (std::string out;; std::this_thread::sleep_for(std::chrono::seconds(2))) {
    const int status = run_shell("squeue -h -j " + job + " -o %i 2>&1", &out);
    if (status == 0 && out.find_first_not_of(" \n") == std::string::npos) return;
    if (status != 0 && out.find("Invalid job id") != std::string::npos) return;
    unreachable = status == 0 ? 0 : unreachable + 1;
    if (unreachable == 30) throw Error("squeue: " + out.substr(0, out.find('\n')) + " (for a minute, waiting for job " + job + ")");
  }
}

}  // namespace

int run_farm_slurm(const FarmPlan& plan, const SlurmSettings& s, bool wait, const Context& ctx) {
  fs::create_directories(plan.parts_dir);
  for (std::size_t k = 0; k < plan.shards.size(); ++k) fs::remove(done_marker(plan, k));
  const std::string array_path = plan.parts_dir + "/shards.sbatch", merge_path = plan.parts_dir + "/merge.sbatch";
  write_file_atomic(array_path, slurm_array_script(plan, s));
  write_file_atomic(merge_path, slurm_merge_script(plan, s));
  const std::string array = submit(array_path, "--array=1-" + std::to_string(plan.shards.size()));
  if (!wait) {
    const std::string merge = submit(merge_path, "--dependency=afterok:" + array + " --kill-on-invalid-dep=yes");
    std::printf("shards: job %s (array of %zu), merge: job %s -> %s\n", array.c_str(), plan.shards.size(), merge.c_str(), plan.out_dir.c_str());
    return 0;
  }
  if (!ctx.quiet()) std::fprintf(stderr, "facetfit: shards: job %s (array of %zu)\n", array.c_str(), plan.shards.size());
  wait_for(array);
  // A shard that did not finish (failed twice inside its task, or was cancelled) is submitted once more.
  std::string again;
  for (std::size_t k = 0; k < plan.shards.size(); ++k)
    if (!fs::exists(done_marker(plan, k))) {
      again += (again.empty() ? "" : ",") + std::to_string(k + 1);
      std::fprintf(stderr, "facetfit: warning: shard %zu (%s) did not finish; submitting it again (log %s/%zu.log)\n", k + 1,
                   shard_names(plan, k).c_str(), plan.parts_dir.c_str(), k + 1);
    }
  if (!again.empty()) wait_for(submit(array_path, "--array=" + again));
  std::size_t missing = 0;
  for (std::size_t k = 0; k < plan.shards.size(); ++k)
    if (!fs::exists(done_marker(plan, k))) {
      ++missing;
      report_error("shard " + std::to_string(k + 1) + " (" + shard_names(plan, k) + ") failed twice; its log: " + plan.parts_dir + "/" +
                   std::to_string(k + 1) + ".log");
    }
  if (missing > 0) {
    report_error(plan.out_dir + ": not published: " + std::to_string(missing) + " of " + std::to_string(plan.shards.size()) + " shards failed");
    return 1;
  }
  fs::remove(plan.parts_dir + "/merge.status");
  const std::string merge = submit(merge_path, "");
  if (!ctx.quiet()) std::fprintf(stderr, "facetfit: merge: job %s\n", merge.c_str());
  wait_for(merge);
  std::ifstream status_file(plan.parts_dir + "/merge.status");
  int status = -1;
  if (!(status_file >> status) || (status != 0 && status != 3)) {
    report_error(plan.out_dir + ": merge failed; its log: " + plan.parts_dir + "/merge.log");
    return 1;
  }
  return status;
}

}  // namespace facetfit::cli
