// bake/core/progress.h — how a long libbake computation reports progress to its caller and how the
// caller cancels it. libbake never draws anything: it calls back, and the tools draw (the terminal
// bar lives in tools/common/progress_bar.h). docs/ARCHITECTURE.md §9.
//
//   Monitor     what the caller hands to a bake: an optional progress callback and an optional
//               cancellation token. A default-constructed Monitor is silent and cannot cancel.
//   Task        what a bake creates for each stage ("baking vertices", "baking FIV shells"): a
//               thread-safe counter that forwards updates to the callback, at most every 50 ms
//               plus once when the stage ends, and never from two threads at once.
//   CancelToken set by the caller from any thread (or a signal handler: one lock-free atomic
//               store); Task::advance then throws Cancelled, which unwinds the bake before any
//               result exists, so a cancelled bake has nothing to write.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>
#include <string_view>

namespace prt::bake {

class CancelToken {
public:
  void request() noexcept { requested_.store(true, std::memory_order_relaxed); }
  bool requested() const noexcept { return requested_.load(std::memory_order_relaxed); }

private:
  std::atomic<bool> requested_{false};
  static_assert(std::atomic<bool>::is_always_lock_free, "request() must be async-signal-safe");
};

// Thrown out of a bake whose CancelToken was requested.
class Cancelled : public std::runtime_error {
public:
  Cancelled() : std::runtime_error("cancelled") {}
};

struct ProgressUpdate {
  std::string_view task;  // the stage, e.g. "baking vertices"
  uint64_t done = 0, total = 0;
  double seconds = 0;     // since the stage started
  bool finished = false;  // the stage's last update (done == total unless it was cancelled)
};

struct Monitor {
  // Called from worker threads, but never concurrently; must not throw.
  std::function<void(const ProgressUpdate&)> on_progress;
  const CancelToken* cancel = nullptr;
  bool cancelled() const noexcept { return cancel && cancel->requested(); }
};

class Task {
public:
  // Throws Cancelled at once if the monitor's token is already requested.
  Task(const Monitor& monitor, std::string label, uint64_t total);
  ~Task();
  Task(const Task&) = delete;
  Task& operator=(const Task&) = delete;

  // Adds n units of finished work; throws Cancelled when cancellation was requested.
  void advance(uint64_t n = 1);
  // Reports the final state once (also done by the destructor).
  void finish() noexcept;
  double elapsed_seconds() const;

private:
  void report(uint64_t done, bool final) noexcept;

  const Monitor& monitor_;
  std::string label_;
  uint64_t total_;
  std::atomic<uint64_t> done_{0};
  std::atomic<int64_t> next_report_ns_{0};
  bool finished_ = false;
  std::mutex report_mutex_;
  std::chrono::steady_clock::time_point start_;
};

// A monitor that folds a sequence of tasks (one per receiver set, one per occluder's shells) into
// one progress stage `label` of `total` units, so that a log shows one stage with one ETA: each
// task's count is offset by `*before` (the units of the tasks already done, which the caller
// advances), the time runs from `start`. The stage finishes with the last task: when `last` is
// null, the task that reaches `total`; else the task during which `*last` is true (a task may end
// short of its share, as FIV shells that stop early). A cancelled task finishes it too.
// `monitor`, `total`, `before` and `last` must outlive the returned monitor.
Monitor fold_tasks(const Monitor& monitor, const std::string& label, const uint64_t& total, const uint64_t& before,
                   std::chrono::steady_clock::time_point start, const bool* last = nullptr);

// The calling thread's CPU time in seconds (CLOCK_THREAD_CPUTIME_ID): what a bake and its
// integrators count as work, since idle or spinning workers do not advance it.
double thread_cpu_seconds();

} // namespace prt::bake
