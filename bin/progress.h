// Progress of a batch on stderr: a bar redrawn in place on a terminal, one plain line per item otherwise
// (logs, CI) and with -v; errors and warnings alone with -q. On a terminal an error or warning takes the
// bar's line (cleared first) and the bar is drawn again below it, never over it. Thread-safe.
#pragma once

#include <unistd.h>

#include <cstdio>
#include <mutex>
#include <string>
#include <vector>

#include "commands.h"

namespace facetfit::cli {

class Progress {
 public:
  Progress(std::size_t total, Verbosity verbosity)
      : total_(total), tty_(verbosity == Verbosity::normal && ::isatty(STDERR_FILENO) == 1), quiet_(verbosity == Verbosity::quiet) {}

  // One item done: `name` on the bar; `line` for logs; an `error` and `warnings` are printed either way.
  void step(const std::string& name, const std::string& line, const std::string& error = "", const std::vector<std::string>& warnings = {}) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++done_;
    failed_ += !error.empty();
    std::vector<std::string> messages;
    if (!error.empty()) messages.push_back("facetfit: error: " + error);
    for (const std::string& w : warnings) messages.push_back("facetfit: warning: " + w);
    if (tty_) {
      for (const std::string& m : messages) std::fprintf(stderr, "\r\033[K%s\n", m.c_str());
      constexpr int kWidth = 30;
      const int filled = int(kWidth * done_ / (total_ > 0 ? total_ : 1));
      const std::string failed = failed_ ? "(" + std::to_string(failed_) + " failed) " : "";
      std::fprintf(stderr, "\r[%-*s] %zu/%zu %s%-30.30s", kWidth, std::string(std::size_t(filled), '=').c_str(), done_, total_,
                   failed.c_str(), name.c_str());
      if (done_ == total_) std::fprintf(stderr, "\n");
    } else {
      for (const std::string& m : messages) std::fprintf(stderr, "%s\n", m.c_str());
      if (error.empty() && !quiet_) std::fprintf(stderr, "%s\n", line.c_str());
    }
    std::fflush(stderr);
  }

 private:
  std::mutex mutex_;
  std::size_t total_, done_ = 0, failed_ = 0;
  bool tty_, quiet_;
};

}  // namespace facetfit::cli
