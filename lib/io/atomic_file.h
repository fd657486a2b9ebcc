// Nothing is lost: every output is written under a temporary name beside its target and renamed into
// place only when complete. A run that stops early (an error, a kill) never leaves a half-written
// file under the target's name.
#pragma once

#include <cstddef>
#include <string>

namespace facetfit {

class AtomicFile {
 public:
  // Picks a hidden temporary name in the target's folder, keeping its extension (image writers choose
  // the format by extension). Throws Error naming `path` when the folder does not exist.
  explicit AtomicFile(std::string path);
  ~AtomicFile();  // removes the temporary unless committed
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::string& path() const { return path_; }
  const std::string& temp_path() const { return temp_; }
  // Flushes the temporary to disk and renames it over the target. Throws Error naming the target.
  void commit();
  // Creates the temporary and removes it again: whether this folder takes a new file at all, asked
  // before work that takes minutes. Throws Error("<path>: cannot write: <reason>").
  void probe() const;

 private:
  std::string path_;
  std::string temp_;
  bool committed_ = false;
};

// Removes temporaries left in `dir` by facetfit runs that no longer exist (a kill mid-write); returns
// how many.
int remove_stale_temporaries(const std::string& dir);

// Makes the output folder `dir` (and its parents) where missing and removes the temporaries killed runs
// left in it. Throws Error("<dir>: cannot create output folder[: reason]").
void prepare_output_folder(const std::string& dir);

// The file a path names, for telling an output from an input: a link and its target, "a/../b" and "b"
// give the same key.
std::string file_key(const std::string& path);

// Writes `content` to `path` through an AtomicFile.
void write_file_atomic(const std::string& path, const std::string& content);

// What is wrong with `name` as the base of an output's name inside its folder (a material's LUT, sidecar
// and image folder), or "" when nothing is: it must be a plain file name, so that no write leaves the
// folder and none is cut short: not empty, "." or "..", no '/' and no control character (NUL ends a path),
// at most kMaxOutputName bytes (a file system's 255, less the temporary's 24 and an extension).
constexpr std::size_t kMaxOutputName = 200;
std::string output_name_problem(const std::string& name);

}  // namespace facetfit
