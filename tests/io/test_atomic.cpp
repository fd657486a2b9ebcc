// Nothing is lost: a writer killed between writing and committing leaves the previous file whole.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "io/atomic_file.h"
#include "lut/bake.h"
#include "test_util.h"

namespace facetfit {
namespace {

using test::TempDir;

// Forks a child that starts replacing `target` with `bytes`, writes half of them and is killed.
void killed_half_way(const std::string& target, const std::string& bytes) {
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    AtomicFile out(target);
    std::FILE* f = std::fopen(out.temp_path().c_str(), "wb");
    std::fwrite(bytes.data(), 1, bytes.size() / 2, f);
    std::fflush(f);
    ::kill(::getpid(), SIGKILL);
    ::_exit(0);  // not reached
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
}

TEST(AtomicFile, OutputNamesAreFileNames) {
  for (const std::string& good : std::vector<std::string>{"gold-ggx-0.15", "x' onerror='y", "a b", std::string(kMaxOutputName, 'n')})
    EXPECT_EQ(output_name_problem(good), "") << good;
  const std::pair<std::string, std::string> bad[] = {{"", "is not a file name"}, {"..", "is not a file name"}, {".", "is not a file name"},
                                                     {"../x", "holds a '/'"}, {"/tmp/x", "holds a '/'"},
                                                     {std::string("x\0y", 3), "control character"}, {"x\ny", "control character"},
                                                     {std::string(kMaxOutputName + 1, 'n'), "bytes long; the limit is 200"}};
  for (const auto& [name, problem] : bad) EXPECT_NE(output_name_problem(name).find(problem), std::string::npos) << name;
}

TEST(AtomicFile, KilledWriterLeavesThePreviousFileWhole) {
  TempDir dir;
  const std::string target = dir.file("gold.exr");
  const std::string old_bytes(100000, 'o'), new_bytes(200000, 'n');
  write_file_atomic(target, old_bytes);
  killed_half_way(target, new_bytes);
  EXPECT_EQ(test::read_bytes(target), old_bytes);
  // The half-written bytes sit under a hidden temporary name, which the next bake removes.
  int hidden = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.path())) hidden += e.path().filename().string()[0] == '.';
  EXPECT_EQ(hidden, 1);
  EXPECT_EQ(remove_stale_temporaries(dir.path().string()), 1);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

TEST(AtomicFile, KilledWriterLeavesNoNewFile) {
  TempDir dir;
  killed_half_way(dir.file("new.json"), std::string(5000, 'x'));
  EXPECT_FALSE(std::filesystem::exists(dir.file("new.json")));
}

TEST(AtomicFile, TemporariesOfLiveWritersAreKept) {
  TempDir dir;
  AtomicFile out(dir.file("busy.exr"));
  test::write_bytes(out.temp_path(), "in progress");
  EXPECT_EQ(remove_stale_temporaries(dir.path().string()), 0);  // this process is alive
  EXPECT_TRUE(std::filesystem::exists(out.temp_path()));
  EXPECT_EQ(std::filesystem::path(out.temp_path()).extension(), ".exr");  // image writers pick the format by it
}

// A writer killed with its shell stays a zombie until its new parent reaps it: it writes nothing more,
// so its temporary goes (the bake kill test left one on a loaded machine).
TEST(AtomicFile, TemporariesOfZombieWritersAreRemoved) {
  TempDir dir;
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) ::_exit(0);
  // Not reaped yet: a zombie once it has exited.
  for (int k = 0; k < 200 && std::filesystem::exists("/proc/" + std::to_string(pid)); ++k) {
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
    if (text.find(") Z") != std::string::npos) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const std::string temporary = dir.file(".x.tmp-" + std::to_string(pid) + "-0000abcd.exr");
  test::write_bytes(temporary, "half");
  EXPECT_EQ(remove_stale_temporaries(dir.path().string()), 1);
  EXPECT_FALSE(std::filesystem::exists(temporary));
  int status = 0;
  ::waitpid(pid, &status, 0);
}

}  // namespace
}  // namespace facetfit
