#include "io/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>

#include "core/error.h"

namespace facetfit {

namespace fs = std::filesystem;

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
  const fs::path target(path_);
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) fail(path_, "cannot write: folder " + dir.string() + " does not exist");
  std::random_device rd;
  const unsigned tag = rd();
  char suffix[64];
  std::snprintf(suffix, sizeof suffix, ".tmp-%ld-%08x", static_cast<long>(::getpid()), tag);
  // The temporary's stem without '?': OpenImageIO reads "name?query" as a file name with options and refuses
  // it as malformed, so a target named "a?b.png" would fail its read-back check.
  std::string stem = target.stem().string();
  std::replace(stem.begin(), stem.end(), '?', '_');
  temp_ = (dir / ("." + stem + suffix + target.extension().string())).string();
}

AtomicFile::~AtomicFile() {
  if (!committed_) ::unlink(temp_.c_str());
}

void AtomicFile::commit() {
  // fsync before rename so that a crash cannot leave a renamed but empty file.
  const int fd = ::open(temp_.c_str(), O_RDONLY);
  if (fd < 0) fail(path_, std::string("cannot write: ") + std::strerror(errno));
  // fsync reports what the writes could not (delayed allocation on a full disk, I/O errors).
  if (::fsync(fd) != 0) {
    const int error = errno;
    ::close(fd);
    fail(path_, std::string("cannot write: ") + std::strerror(error));
  }
  ::close(fd);
  if (std::rename(temp_.c_str(), path_.c_str()) != 0)
    fail(path_, std::string("cannot write: ") + std::strerror(errno));
  committed_ = true;
}

void AtomicFile::probe() const {
  const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
  if (fd < 0) fail(path_, std::string("cannot write: ") + std::strerror(errno));
  ::close(fd);
  ::unlink(temp_.c_str());
}

std::string file_key(const std::string& path) {
  std::error_code ec;
  const fs::path canonical = fs::weakly_canonical(fs::absolute(path), ec);
  return (ec ? fs::absolute(path).lexically_normal() : canonical).string();
}

void write_file_atomic(const std::string& path, const std::string& content) {
  AtomicFile out(path);
  std::FILE* f = std::fopen(out.temp_path().c_str(), "wb");
  if (!f) fail(path, std::string("cannot write: ") + std::strerror(errno));
  const bool ok = std::fwrite(content.data(), 1, content.size(), f) == content.size();
  if (std::fclose(f) != 0 || !ok) fail(path, "cannot write: short write (disk full?)");
  out.commit();
}

namespace {

// The writer's pid if `file` is an AtomicFile temporary, .<stem>.tmp-<pid>-<8 hex digits>[.<ext>]; else 0.
long temporary_owner(const std::string& file) {
  const std::size_t at = file.rfind(".tmp-");
  if (file.empty() || file[0] != '.' || at == std::string::npos || at == 0) return 0;
  std::size_t k = at + 5, digits = 0;
  long pid = 0;
  for (; k < file.size() && std::isdigit(static_cast<unsigned char>(file[k])) && digits < 10; ++k, ++digits) pid = pid * 10 + (file[k] - '0');
  if (digits == 0 || k >= file.size() || file[k] != '-') return 0;
  std::size_t hex = 0;
  for (++k; k < file.size() && std::isxdigit(static_cast<unsigned char>(file[k])); ++k) ++hex;
  if (hex != 8 || (k < file.size() && file[k] != '.')) return 0;
  return pid;
}

// Whether process `pid` still runs: it exists and is not a zombie (a writer killed with its shell is
// reparented and stays a zombie until its new parent reaps it, which on a loaded machine can come after
// the next run has started).
bool is_running(long pid) {
  if (::kill(pid_t(pid), 0) != 0) return false;
  std::FILE* f = std::fopen(("/proc/" + std::to_string(pid) + "/stat").c_str(), "r");
  if (!f) return true;  // no /proc: trust kill()
  char buffer[512] = {};
  const std::size_t n = std::fread(buffer, 1, sizeof buffer - 1, f);
  std::fclose(f);
  // "pid (comm) S ...": the state follows the last ')' (comm may hold parentheses and spaces).
  const char* close = std::strrchr(buffer, ')');
  if (n == 0 || !close || close[1] != ' ') return true;
  return close[2] != 'Z' && close[2] != 'X';
}

}  // namespace

void prepare_output_folder(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir)) fail(dir, "cannot create output folder" + (ec ? ": " + ec.message() : std::string()));
  remove_stale_temporaries(dir);
}

std::string output_name_problem(const std::string& name) {
  if (name.empty() || name == "." || name == "..") return "is not a file name";
  if (name.size() > kMaxOutputName) return "is " + std::to_string(name.size()) + " bytes long; the limit is " + std::to_string(kMaxOutputName);
  for (const char c : name) {
    if (c == '/') return "holds a '/': it must be a file name, not a path";
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return "holds a control character";
  }
  return "";
}

int remove_stale_temporaries(const std::string& dir) {
  int removed = 0;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const long pid = temporary_owner(entry.path().filename().string());
    if (pid <= 0) continue;
    if (is_running(pid)) continue;  // its writer is still writing
    if (fs::remove(entry.path(), ec)) ++removed;
  }
  return removed;
}

}  // namespace facetfit
