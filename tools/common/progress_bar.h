// tools/common/progress_bar.h — the tools' side of libbake's progress callbacks (bake/progress.h):
// draws what the library reports. libbake itself never writes to the terminal.
//
//   Bar:   on a terminal, one self-overwriting line on stderr:
//          "baking vertices [#########.........] 52%  2210/4240  1.9k/s  ETA 1.1s"
//   Lines: when stderr is not a terminal (CI logs, pipes), a plain line at every 10%.
//   Quiet: nothing (--quiet).
#pragma once

#include <bake/progress.h>

#include <string>

namespace prt::tool {

enum class ProgressStyle { Auto, Bar, Lines, Quiet };

class ProgressBar {
public:
  explicit ProgressBar(ProgressStyle style);
  // A monitor whose updates this bar draws and which cancels with `cancel` (may be null).
  bake::Monitor monitor(const bake::CancelToken* cancel) const;

private:
  void draw(const bake::ProgressUpdate& u) const;
  ProgressStyle style_;
  mutable std::string task_;  // the stage being drawn
  mutable int last_decile_ = -1;
};

} // namespace prt::tool
