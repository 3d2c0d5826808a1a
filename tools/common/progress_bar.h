// tools/common/progress_bar.h — the tools' side of libbake's progress callbacks (bake/core/progress.h):
// draws what the library reports. libbake itself never writes to the terminal.
//
//   Bar:   on a terminal, one self-overwriting line on stderr:
//          "baking vertices [#########.........] 52%  2210/4240  1.9k/s  ETA 1.1s"
//   Lines: when stderr is not a terminal (CI logs, pipes), a few plain lines per stage:
//          "baking vertices:  25% (1060/4240) 1.9k/s, 1.2s, ETA 3.4s". A stage's first line comes
//          once it has run kFirstLineSeconds (a shorter stage prints nothing: its result is on
//          stdout), then a line when it passes 25%, 50% or 75% at least kLineSpacingSeconds after
//          its last one, and an end line; so a log holds at most five lines per stage, and none
//          for the many short stages of a scene.
//   Quiet: nothing (--quiet).
#pragma once

#include <bake/core/progress.h>

#include <string>

namespace prt::tool {

enum class ProgressStyle { Auto, Bar, Lines, Quiet };

class ProgressBar {
public:
  static constexpr double kFirstLineSeconds = 1.0;
  static constexpr double kLineSpacingSeconds = 10.0;

  explicit ProgressBar(ProgressStyle style);
  // A monitor whose updates this bar draws and which cancels with `cancel` (may be null).
  bake::Monitor monitor(const bake::CancelToken* cancel) const;

private:
  void draw(const bake::ProgressUpdate& u) const;
  ProgressStyle style_;
  mutable std::string task_;       // the stage being drawn
  mutable bool stage_ended_ = true;  // its last update was the final one: the next starts a stage
  mutable bool printed_ = false;     // Lines: a line of this stage was printed
  mutable int last_quarter_ = 0;     // Lines: the quarter (0-3) of its last line
  mutable double last_line_seconds_ = 0;
};

} // namespace prt::tool
