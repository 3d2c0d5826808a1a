// What every tool shares (tools/common): run_tool's mapping from what a tool throws to one stderr
// line and an exit code (tool_main.h), the Ctrl-C token, and the non-terminal progress lines
// (progress_bar.h).
#include <bake/error.h>
#include <bake/progress.h>
#include <formats/prtfile.h>
#include <progress_bar.h>
#include <tool_main.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

using namespace prt;

namespace {

// The body run_tool runs: throws what argv[1] names ("return" returns 0).
int thrower(int argc, char** argv) {
  const std::string what = argc > 1 ? argv[1] : "";
  if (what == "input") throw bake::InputError("mesh.obj", "face 3 has 2 vertices");
  if (what == "format") throw formats::FormatError("bake.h5", "no dataset /mesh/position");
  if (what == "usage") throw tool::UsageError("--samples must be at least 1");
  if (what == "system") throw bake::SystemError("Embree device: out of memory");
  if (what == "bad_alloc") throw std::bad_alloc();
  if (what == "contract") PRT_CHECK_OP(argc, ==, 7);
  if (what == "runtime") throw std::runtime_error("unexpected");
  if (what == "cancelled") throw bake::Cancelled();
  if (what == "int") throw 42;
  return 0;
}

struct Ending {
  int code;
  std::string err;
};

Ending run(const std::string& kind) {
  std::string arg0 = "prtfake", arg1 = kind;
  char* argv[] = {arg0.data(), arg1.data(), nullptr};
  ::testing::internal::CaptureStderr();
  const int code = tool::run_tool("prtfake", thrower, 2, argv);
  return {code, ::testing::internal::GetCapturedStderr()};
}

} // namespace

TEST(RunTool, EachKindOfFailureHasItsExitCodeAndOneLine) {
  struct Case {
    const char* kind;
    int code;
    const char* line;
  };
  const Case cases[] = {
      {"return", 0, ""},
      {"input", 1, "prtfake: error: mesh.obj: face 3 has 2 vertices\n"},
      {"format", 1, "prtfake: error: bake.h5: no dataset /mesh/position\n"},
      {"usage", 2, "prtfake: --samples must be at least 1 (try 'prtfake --help')\n"},
      {"system", 3, "prtfake: system error: Embree device: out of memory\n"},
      {"bad_alloc", 3, "prtfake: system error: out of memory\n"},
      {"runtime", 4, "prtfake: internal error: unexpected\n"},
      {"int", 4, "prtfake: internal error: unknown exception\n"},
      {"cancelled", 130, "prtfake: cancelled; nothing was written\n"},
  };
  for (const Case& c : cases) {
    const Ending e = run(c.kind);
    EXPECT_EQ(e.code, c.code) << c.kind;
    EXPECT_EQ(e.err, c.line) << c.kind;
  }
  // The codes are the ones --help documents.
  EXPECT_EQ(int(tool::kExitBadInput), 1);
  EXPECT_EQ(int(tool::kExitUsage), 2);
  EXPECT_EQ(int(tool::kExitSystem), 3);
  EXPECT_EQ(int(tool::kExitInternal), 4);
  EXPECT_EQ(int(tool::kExitCancelled), 130);
  for (const char* code : {"  0 ", "  1 ", "  2 ", "  3 ", "  4 ", "  130 "})
    EXPECT_NE(std::string(tool::kExitStatusHelp).find(code), std::string::npos) << code;
}

TEST(RunTool, ABrokenContractIsAnInternalErrorThatSaysWhere) {
  const Ending e = run("contract");
  EXPECT_EQ(e.code, 4);
  EXPECT_EQ(e.err.rfind("prtfake: internal error: ", 0), 0u) << e.err;
  EXPECT_NE(e.err.find("test_tool_common.cpp:"), std::string::npos) << e.err;
  EXPECT_NE(e.err.find("check failed: argc == 7 (2 vs 7)"), std::string::npos) << e.err;
  EXPECT_EQ(std::count(e.err.begin(), e.err.end(), '\n'), 1) << e.err;
}

TEST(InterruptHandler, FirstCtrlCRequestsTheTokenSecondKills) {
  EXPECT_FALSE(tool::interrupt_token().requested());
  tool::install_interrupt_handler();
  std::raise(SIGINT);
  EXPECT_TRUE(tool::interrupt_token().requested()) << "the first SIGINT cancels cleanly";
  // The second one ends the process by the signal itself (the shell then sees 128 + 2).
  EXPECT_EXIT(std::raise(SIGINT), ::testing::KilledBySignal(SIGINT), "");
}

namespace {
// The lines a non-terminal progress display prints for `updates` of one 100-unit stage.
std::vector<std::string> progress_lines(tool::ProgressStyle style, const std::vector<std::pair<uint64_t, bool>>& updates) {
  const tool::ProgressBar bar(style);
  const bake::Monitor m = bar.monitor(nullptr);
  ::testing::internal::CaptureStderr();
  for (const auto& [done, finished] : updates) {
    bake::ProgressUpdate u;
    u.task = "baking things";
    u.total = 100;
    u.done = done;
    u.seconds = 0.5;
    u.finished = finished;
    if (m.on_progress) m.on_progress(u);
  }
  const std::string err = ::testing::internal::GetCapturedStderr();
  std::vector<std::string> lines;
  for (size_t a = 0, b; (b = err.find('\n', a)) != std::string::npos; a = b + 1) lines.push_back(err.substr(a, b - a));
  return lines;
}
} // namespace

TEST(ProgressBar, LinesStyleOnePerTenthAndNoRepeatAtTheEnd) {
  std::vector<std::pair<uint64_t, bool>> all;
  for (uint64_t d = 0; d <= 100; ++d) all.push_back({d, false});
  all.push_back({100, true});
  const auto lines = progress_lines(tool::ProgressStyle::Lines, all);
  ASSERT_EQ(lines.size(), 11u);  // 0%, 10%, …, 100%; the final update repeats nothing
  EXPECT_EQ(lines.front().rfind("baking things:   0% (0/100)", 0), 0u) << lines.front();
  EXPECT_EQ(lines.back().rfind("baking things: 100% (100/100)", 0), 0u) << lines.back();

  // A cancelled stage ends with its own line at the count it reached.
  const auto cancelled = progress_lines(tool::ProgressStyle::Lines, {{0, false}, {55, false}, {55, true}});
  ASSERT_EQ(cancelled.size(), 3u);
  EXPECT_EQ(cancelled.back().rfind("baking things:  55% (55/100)", 0), 0u) << cancelled.back();

  EXPECT_TRUE(progress_lines(tool::ProgressStyle::Quiet, all).empty());
}

TEST(ProgressBar, MonitorCarriesTheCancelToken) {
  bake::CancelToken token;
  const tool::ProgressBar bar(tool::ProgressStyle::Quiet);
  const bake::Monitor m = bar.monitor(&token);
  EXPECT_FALSE(m.on_progress) << "--quiet installs no callback";
  EXPECT_FALSE(m.cancelled());
  token.request();
  EXPECT_TRUE(m.cancelled());
}
