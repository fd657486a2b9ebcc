// An advisory lock (flock) on an output folder, held for the object's life: processes (and threads) that
// update the same outputs, a LUT with its sidecar, or index.json, take turns. The folder itself is
// locked, so no lock file is left behind.
#pragma once

#include <string>

namespace facetfit {

class FolderLock {
 public:
  // Blocks until the lock is held (Wait::no: throws Error("<folder>: is being written by another facetfit
  // process") when another holds it). Throws Error("<folder>: cannot lock: <reason>").
  enum class Wait { yes, no };
  explicit FolderLock(const std::string& folder, Wait wait = Wait::yes);
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace facetfit
