#include <bake/progress.h>

#include <algorithm>
#include <cstdio>
#include <unistd.h>

namespace prt::bake {

ProgressMode resolve_progress_mode(ProgressMode mode) {
  if (mode != ProgressMode::Auto) return mode;
  return isatty(STDERR_FILENO) ? ProgressMode::Bar : ProgressMode::Lines;
}

Progress::Progress(std::string label, uint64_t total, ProgressMode mode)
    : label_(std::move(label)), total_(std::max<uint64_t>(total, 1)), mode_(resolve_progress_mode(mode)),
      start_(std::chrono::steady_clock::now()) {}

Progress::~Progress() { finish(); }

double Progress::elapsed_seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::advance(uint64_t n) {
  const uint64_t done = done_.fetch_add(n, std::memory_order_relaxed) + n;
  if (mode_ == ProgressMode::Quiet) return;
  const int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                          std::chrono::steady_clock::now() - start_).count();
  int64_t next = next_draw_ns_.load(std::memory_order_relaxed);
  if (now < next) return;
  if (!next_draw_ns_.compare_exchange_strong(next, now + 100'000'000)) return;  // another thread draws
  std::unique_lock lock(draw_mutex_, std::try_to_lock);
  if (lock.owns_lock() && !finished_) draw(done, false);
}

void Progress::finish() {
  std::lock_guard lock(draw_mutex_);
  if (finished_) return;
  finished_ = true;
  if (mode_ != ProgressMode::Quiet) draw(done_.load(), true);
}

static std::string human_rate(double per_second) {
  char buf[32];
  if (per_second >= 1e6) std::snprintf(buf, sizeof buf, "%.1fM/s", per_second / 1e6);
  else if (per_second >= 1e3) std::snprintf(buf, sizeof buf, "%.1fk/s", per_second / 1e3);
  else std::snprintf(buf, sizeof buf, "%.1f/s", per_second);
  return buf;
}

void Progress::draw(uint64_t done, bool final) {
  done = std::min(done, total_);
  const double t = elapsed_seconds();
  const double frac = double(done) / double(total_);
  const double rate = t > 0 ? double(done) / t : 0.0;
  const double eta = rate > 0 ? double(total_ - done) / rate : 0.0;
  if (mode_ == ProgressMode::Bar) {
    constexpr int kWidth = 30;
    const int filled = int(frac * kWidth);
    std::string bar(size_t(filled), '#');
    bar.append(size_t(kWidth - filled), '.');
    std::fprintf(stderr, "\r%s [%s] %3d%%  %llu/%llu  %s  %s %.1fs\033[K%s", label_.c_str(), bar.c_str(),
                 int(frac * 100), (unsigned long long)done, (unsigned long long)total_, human_rate(rate).c_str(),
                 final ? "took" : "ETA", final ? t : eta, final ? "\n" : "");
  } else {
    const int decile = int(frac * 10);
    if (decile == last_decile_ && !final) return;
    if (final && decile == last_decile_ && done == total_ && last_decile_ == 10) return;
    last_decile_ = decile;
    std::fprintf(stderr, "%s: %3d%% (%llu/%llu) %s, %.1fs\n", label_.c_str(), int(frac * 100),
                 (unsigned long long)done, (unsigned long long)total_, human_rate(rate).c_str(), t);
  }
  std::fflush(stderr);
}

} // namespace prt::bake
