#include "progress_bar.h"

#include <algorithm>
#include <cstdio>
#include <unistd.h>

namespace prt::tool {

namespace {
std::string human_rate(double per_second) {
  char buf[32];
  if (per_second >= 1e6) std::snprintf(buf, sizeof buf, "%.1fM/s", per_second / 1e6);
  else if (per_second >= 1e3) std::snprintf(buf, sizeof buf, "%.1fk/s", per_second / 1e3);
  else std::snprintf(buf, sizeof buf, "%.1f/s", per_second);
  return buf;
}
} // namespace

ProgressBar::ProgressBar(ProgressStyle style) : style_(style) {
  if (style_ == ProgressStyle::Auto) style_ = isatty(STDERR_FILENO) ? ProgressStyle::Bar : ProgressStyle::Lines;
}

bake::Monitor ProgressBar::monitor(const bake::CancelToken* cancel) const {
  bake::Monitor m;
  m.cancel = cancel;
  if (style_ != ProgressStyle::Quiet) m.on_progress = [this](const bake::ProgressUpdate& u) { draw(u); };
  return m;
}

// Called by libbake's Task, never concurrently for one task; tasks run one after another.
void ProgressBar::draw(const bake::ProgressUpdate& u) const {
  if (u.task != task_ || stage_ended_) {  // a new stage (two in a row may share a label)
    task_ = std::string(u.task);
    printed_ = false;
    last_quarter_ = 0;
  }
  stage_ended_ = u.finished;
  if (u.total == 0) return;
  const double frac = double(u.done) / double(u.total);
  const double rate = u.seconds > 0 ? double(u.done) / u.seconds : 0.0;
  const double eta = rate > 0 ? double(u.total - u.done) / rate : 0.0;
  if (style_ == ProgressStyle::Bar) {
    constexpr int kWidth = 30;
    const int filled = int(frac * kWidth);
    std::string bar(size_t(filled), '#');
    bar.append(size_t(kWidth - filled), '.');
    std::fprintf(stderr, "\r%s [%s] %3d%%  %llu/%llu  %s  %s %.1fs\033[K%s", task_.c_str(), bar.c_str(),
                 int(frac * 100), (unsigned long long)u.done, (unsigned long long)u.total, human_rate(rate).c_str(),
                 u.finished ? "took" : "ETA", u.finished ? u.seconds : eta, u.finished ? "\n" : "");
  } else {
    const int quarter = std::min(int(frac * 4), 3);
    if (u.finished) {
      if (!printed_ && u.seconds < kFirstLineSeconds) return;  // a short stage: silent
    } else if (!printed_) {
      if (u.seconds < kFirstLineSeconds) return;
    } else if (quarter <= last_quarter_ || u.seconds - last_line_seconds_ < kLineSpacingSeconds) {
      return;
    }
    printed_ = true;
    last_quarter_ = quarter;
    last_line_seconds_ = u.seconds;
    std::fprintf(stderr, "%s: %3d%% (%llu/%llu) %s, %.1fs", task_.c_str(), int(frac * 100), (unsigned long long)u.done,
                 (unsigned long long)u.total, human_rate(rate).c_str(), u.seconds);
    if (!u.finished && rate > 0) std::fprintf(stderr, ", ETA %.1fs", eta);
    std::fputc('\n', stderr);
  }
  std::fflush(stderr);
}

} // namespace prt::tool
