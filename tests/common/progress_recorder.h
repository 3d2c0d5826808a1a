// A progress callback for tests (bake/core/progress.h): records every update a Monitor's callback
// receives and counts calls that overlapped (the contract says they never do).
#pragma once

#include <bake/core/progress.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

namespace prt::testing {

// Every update a callback saw, and whether two calls ever overlapped.
struct Recorder {
  std::vector<bake::ProgressUpdate> updates;  // task views point into the Task's label: compare at once
  std::vector<std::string> tasks;
  std::atomic<bool> inside{false};
  std::atomic<int> overlaps{0};
  std::function<void(const bake::ProgressUpdate&)> then;  // runs inside the callback (e.g. to cancel)
  std::chrono::microseconds dwell{200};                    // time spent in each call

  bake::Monitor monitor(const bake::CancelToken* cancel = nullptr) {
    bake::Monitor m;
    m.cancel = cancel;
    m.on_progress = [this](const bake::ProgressUpdate& u) {
      if (inside.exchange(true)) ++overlaps;
      std::this_thread::sleep_for(dwell);  // widens the window for an overlap
      updates.push_back(u);
      tasks.emplace_back(u.task);
      if (then) then(u);
      inside.store(false);
    };
    return m;
  }
};

// One stage that ran to its end: every update names `task` and `total`, counts never go back or
// pass the total, the first is 0 and only the last is finished, at done == total; no overlaps.
inline void expect_complete_stage(const Recorder& rec, std::string_view task, uint64_t total) {
  EXPECT_EQ(rec.overlaps.load(), 0) << "two callbacks ran at the same time";
  ASSERT_FALSE(rec.updates.empty());
  uint64_t previous = 0;
  double previous_seconds = 0;
  for (size_t i = 0; i < rec.updates.size(); ++i) {
    const bake::ProgressUpdate& u = rec.updates[i];
    EXPECT_EQ(rec.tasks[i], task) << "update " << i;
    EXPECT_EQ(u.total, total) << "update " << i;
    EXPECT_LE(u.done, u.total) << "update " << i;
    EXPECT_GE(u.done, previous) << "update " << i << " went backwards";
    EXPECT_GE(u.seconds, previous_seconds) << "update " << i;
    EXPECT_EQ(u.finished, i + 1 == rec.updates.size()) << "exactly one finished update, the last (update " << i << ")";
    previous = u.done;
    previous_seconds = u.seconds;
  }
  EXPECT_EQ(rec.updates.front().done, 0u);
  EXPECT_EQ(rec.updates.back().done, total);
}

} // namespace prt::testing
