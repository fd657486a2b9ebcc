// Small helpers shared by the tests.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "core/error.h"
#include "core/vec.h"

namespace facetfit::test {

// A fresh folder under the system temp folder, removed with everything in it at scope exit.
class TempDir {
 public:
  TempDir() {
    std::string templ = (std::filesystem::temp_directory_path() / "facetfit-test-XXXXXX").string();
    if (!::mkdtemp(templ.data())) throw std::runtime_error("mkdtemp failed");
    path_ = templ;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::permissions(path_, std::filesystem::perms::owner_all, ec);
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

inline std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The message of the facetfit::Error that `f` throws, or "" if it throws none.
template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// The 12-byte header of a MERL file claiming these dimensions.
inline std::string merl_header(std::int32_t a, std::int32_t b, std::int32_t c) {
  std::string s(12, '\0');
  std::memcpy(s.data(), &a, 4);
  std::memcpy(s.data() + 4, &b, 4);
  std::memcpy(s.data() + 8, &c, 4);
  return s;
}

// A direction uniformly distributed over the upper hemisphere.
inline Vec3 random_direction(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double cos_theta = u(rng);
  return spherical_direction(std::acos(cos_theta), 2.0 * kPi * u(rng));
}

// The RGL material database: FACETFIT_RGL_DIR, or ../shared/data/rgl beside the source tree.
inline std::filesystem::path rgl_dir() {
  if (const char* env = std::getenv("FACETFIT_RGL_DIR"); env && *env) return env;
  return std::filesystem::path(FACETFIT_SOURCE_DIR) / ".." / "shared" / "data" / "rgl";
}

struct RunResult {
  int status = -1;
  std::string out, err;
};

// Runs a shell command line, capturing stdout and stderr.
inline RunResult run_command(const std::string& command) {
  TempDir dir;
  const std::string cmd = command + " >" + dir.file("out") + " 2>" + dir.file("err");
  RunResult r;
  const int raw = std::system(cmd.c_str());
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = read_bytes(dir.file("out"));
  r.err = read_bytes(dir.file("err"));
  return r;
}

#ifdef FACETFIT_CLI
// Runs the facetfit command with `args` (shell words).
inline RunResult facetfit(const std::string& args) { return run_command(std::string(FACETFIT_CLI) + " " + args); }
#endif

// The unit direction at elevation theta_deg (degrees) and azimuth phi (radians).
inline Vec3 direction_at(double theta_deg, double phi = 0.3) { return spherical_direction(theta_deg * kPi / 180.0, phi); }

}  // namespace facetfit::test
