// bake/progress.h — progress reporting for long work, safe to call from many threads.
//
//   Bar:   on a terminal, one self-overwriting line on stderr:
//          "baking vertices [#########.........] 52%  2210/4240  1.9k/s  ETA 1.1s"
//   Lines: when stderr is not a terminal (CI logs, pipes), a plain line at every 10%.
//   Quiet: nothing (--quiet).
// advance() is cheap (one atomic add); drawing happens at most every 100 ms, from whichever
// thread crosses the deadline.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace prt::bake {

enum class ProgressMode { Auto, Bar, Lines, Quiet };

class Progress {
public:
  Progress(std::string label, uint64_t total, ProgressMode mode = ProgressMode::Auto);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void advance(uint64_t n = 1);
  void finish();  // draws the final state once; also called by the destructor
  double elapsed_seconds() const;

private:
  void draw(uint64_t done, bool final);

  std::string label_;
  uint64_t total_;
  ProgressMode mode_;
  std::atomic<uint64_t> done_{0};
  std::atomic<int64_t> next_draw_ns_{0};
  int last_decile_ = -1;
  bool finished_ = false;
  std::mutex draw_mutex_;
  std::chrono::steady_clock::time_point start_;
};

// Resolves Auto to Bar or Lines by whether stderr is a terminal.
ProgressMode resolve_progress_mode(ProgressMode mode);

} // namespace prt::bake
