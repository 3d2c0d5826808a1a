#include <bake/core/progress.h>

#include <ctime>

#include <algorithm>

namespace prt::bake {

namespace {
constexpr int64_t kReportIntervalNs = 50'000'000;  // 50 ms: the tools redraw at most this often
}

Task::Task(const Monitor& monitor, std::string label, uint64_t total)
    : monitor_(monitor), label_(std::move(label)), total_(total), start_(std::chrono::steady_clock::now()) {
  if (monitor_.cancelled()) throw Cancelled();
  report(0, false);
}

Task::~Task() { finish(); }

double Task::elapsed_seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Task::advance(uint64_t n) {
  done_.fetch_add(n, std::memory_order_relaxed);
  if (monitor_.cancelled()) throw Cancelled();
  if (!monitor_.on_progress) return;
  const int64_t now =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start_).count();
  int64_t next = next_report_ns_.load(std::memory_order_relaxed);
  if (now < next) return;
  if (!next_report_ns_.compare_exchange_strong(next, now + kReportIntervalNs)) return;  // another thread reports
  std::unique_lock lock(report_mutex_, std::try_to_lock);
  // The count is read under the lock that orders the reports, so they never go backwards (a
  // thread stalled between winning the exchange and locking must not report an older count).
  if (lock.owns_lock() && !finished_) report(done_.load(std::memory_order_relaxed), false);
}

void Task::finish() noexcept {
  std::lock_guard lock(report_mutex_);
  if (finished_) return;
  finished_ = true;
  report(done_.load(), true);
}

void Task::report(uint64_t done, bool final) noexcept {
  if (!monitor_.on_progress) return;
  ProgressUpdate u;
  u.task = label_;
  u.total = total_;
  u.done = std::min(done, total_);
  u.seconds = elapsed_seconds();
  u.finished = final;
  monitor_.on_progress(u);
}

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

Monitor fold_tasks(const Monitor& monitor, const std::string& label, const uint64_t& total, const uint64_t& before,
                   std::chrono::steady_clock::time_point start, const bool* last) {
  Monitor m;
  m.cancel = monitor.cancel;
  if (monitor.on_progress)
    m.on_progress = [&monitor, label, &total, &before, start, last](const ProgressUpdate& u) {
      ProgressUpdate o = u;
      o.task = label;
      o.done = before + u.done;
      o.total = total;
      o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (!last) {
        o.finished = u.finished && (o.done == o.total || u.done < u.total);  // the last task, or a cancel
      } else {
        o.finished = u.finished && (*last || monitor.cancelled());
        if (o.finished && !monitor.cancelled()) o.done = total;  // the last task may end short of its share
      }
      monitor.on_progress(o);
    };
  return m;
}

} // namespace prt::bake
