// What every tool shares (tools/common): run_tool's mapping from what a tool throws to one stderr
// line and an exit code (tool_main.h), the Ctrl-C token, the non-terminal progress lines
// (progress_bar.h), and the command-line checks and suggestions (cli.h).
#include <bake/core/error.h>
#include <bake/core/progress.h>
#include <formats/prtfile.h>
#include <cli.h>
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
  if (what == "usage_in") throw tool::UsageError("fiv: --cube must be at least 1", "prtfake fiv");
  if (what == "system") throw bake::SystemError("Embree device: out of memory");
  if (what == "bad_alloc") throw std::bad_alloc();
  if (what == "contract") PRT_CHECK_OP(argc, ==, 7);
  if (what == "runtime") throw std::runtime_error("unexpected");
  if (what == "cancelled") throw bake::Cancelled();
  if (what == "kept") throw tool::CancelledKeeping("3 of 9 chunks are committed and kept in out.chunks/");
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
      {"usage_in", 2, "prtfake: fiv: --cube must be at least 1 (try 'prtfake fiv --help')\n"},
      {"system", 3, "prtfake: system error: Embree device: out of memory\n"},
      {"bad_alloc", 3, "prtfake: system error: out of memory\n"},
      {"runtime", 4, "prtfake: internal error: unexpected\n"},
      {"int", 4, "prtfake: internal error: unknown exception\n"},
      {"cancelled", 130, "prtfake: cancelled; nothing was written\n"},
      {"kept", 130, "prtfake: cancelled; 3 of 9 chunks are committed and kept in out.chunks/\n"},
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
struct Update {
  uint64_t done;
  double seconds;
  bool finished = false;
};
// The lines a non-terminal progress display prints for `updates` of one 100-unit stage.
std::vector<std::string> progress_lines(tool::ProgressStyle style, const std::vector<Update>& updates,
                                        const char* task = "baking things") {
  const tool::ProgressBar bar(style);
  const bake::Monitor m = bar.monitor(nullptr);
  ::testing::internal::CaptureStderr();
  for (const Update& x : updates) {
    bake::ProgressUpdate u;
    u.task = task;
    u.total = 100;
    u.done = x.done;
    u.seconds = x.seconds;
    u.finished = x.finished;
    if (m.on_progress) m.on_progress(u);
  }
  const std::string err = ::testing::internal::GetCapturedStderr();
  std::vector<std::string> lines;
  for (size_t a = 0, b; (b = err.find('\n', a)) != std::string::npos; a = b + 1) lines.push_back(err.substr(a, b - a));
  return lines;
}

// A stage of `seconds` reported every 50 ms (as bake::Task does), at a steady rate.
std::vector<Update> steady_stage(double seconds) {
  std::vector<Update> u;
  const int steps = int(seconds / 0.05);
  for (int i = 0; i <= steps; ++i) u.push_back({uint64_t(100 * i / steps), 0.05 * i});
  u.push_back({100, seconds, true});
  return u;
}
} // namespace

TEST(ProgressBar, LinesStyleIsAFewLinesPerStageAndNoneForAShortOne) {
  // Under a second: nothing (its result is on stdout).
  EXPECT_TRUE(progress_lines(tool::ProgressStyle::Lines, steady_stage(0.8)).empty());
  // A few seconds: its first line once it has run a second, and its end.
  const auto short_stage = progress_lines(tool::ProgressStyle::Lines, steady_stage(4));
  ASSERT_EQ(short_stage.size(), 2u);
  EXPECT_EQ(short_stage.front().rfind("baking things:  25% (25/100)", 0), 0u) << short_stage.front();
  EXPECT_NE(short_stage.front().find(", ETA 3.0s"), std::string::npos) << short_stage.front();
  EXPECT_EQ(short_stage.back().rfind("baking things: 100% (100/100)", 0), 0u) << short_stage.back();
  EXPECT_EQ(short_stage.back().find("ETA"), std::string::npos) << short_stage.back();
  // A minute: the first line (at 1 s), 25%, 50% and 75% (each at least 10 s after the line
  // before it), and the end: five lines.
  const auto long_stage = progress_lines(tool::ProgressStyle::Lines, steady_stage(60));
  ASSERT_EQ(long_stage.size(), 5u);
  EXPECT_EQ(long_stage[0].rfind("baking things:   1% (1/100)", 0), 0u) << long_stage[0];
  EXPECT_EQ(long_stage[1].rfind("baking things:  25% (25/100)", 0), 0u) << long_stage[1];
  EXPECT_EQ(long_stage[2].rfind("baking things:  50% (50/100)", 0), 0u) << long_stage[2];
  EXPECT_EQ(long_stage[3].rfind("baking things:  75% (75/100)", 0), 0u) << long_stage[3];
  EXPECT_EQ(long_stage[4].rfind("baking things: 100% (100/100)", 0), 0u) << long_stage[4];
  // Quarters passed within 10 s of the last line wait: 12 s gives the first line (8%), one line at
  // 11 s (91%: the first update 10 s after it, in a quarter not yet shown), and the end.
  EXPECT_EQ(progress_lines(tool::ProgressStyle::Lines, steady_stage(12)).size(), 3u);

  // A cancelled stage ends with its own line at the count it reached.
  const auto cancelled = progress_lines(tool::ProgressStyle::Lines, {{0, 0}, {55, 2.0}, {55, 2.1, true}});
  ASSERT_EQ(cancelled.size(), 2u);
  EXPECT_EQ(cancelled.back().rfind("baking things:  55% (55/100)", 0), 0u) << cancelled.back();

  // Two stages in a row with one label are two stages.
  std::vector<Update> twice = steady_stage(3);
  for (const Update& u : steady_stage(3)) twice.push_back(u);
  EXPECT_EQ(progress_lines(tool::ProgressStyle::Lines, twice).size(), 4u);

  EXPECT_TRUE(progress_lines(tool::ProgressStyle::Quiet, steady_stage(60)).empty());
}

TEST(CommandLine, SuggestionsAreTheNearestNameOrNone) {
  EXPECT_EQ(tool::edit_distance("radiance", "radiance"), 0u);
  EXPECT_EQ(tool::edit_distance("radiancee", "radiance"), 1u);
  EXPECT_EQ(tool::edit_distance("raidance", "radiance"), 1u) << "a swap of neighbours is one edit";
  EXPECT_EQ(tool::edit_distance("", "abc"), 3u);
  EXPECT_EQ(tool::edit_distance("kitten", "sitting"), 3u);
  const std::vector<std::string> options = {"--ao", "--transfer", "--radiance", "--env", "--samples", "-o", "--output"};
  EXPECT_EQ(tool::closest("--radiancee", options), "--radiance");
  EXPECT_EQ(tool::closest("--sample", options), "--samples");
  EXPECT_EQ(tool::closest("--tranfser", options), "--transfer");
  EXPECT_EQ(tool::closest("--environment", options), "--env") << "a whole name that begins the word";
  EXPECT_EQ(tool::closest("--frobnicate", options), std::nullopt) << "nothing near: no guess";
  const std::vector<std::string> commands = {"vertex", "fiv", "scene", "export"};
  EXPECT_EQ(tool::closest("vertx", commands), "vertex");
  EXPECT_EQ(tool::closest("exprot", commands), "export");
  EXPECT_EQ(tool::closest("bake", commands), std::nullopt);
}

TEST(CommandLine, NumberChecksSayWhatIsWrongWithTheValue) {
  const auto check = [](const CLI::Validator& v, std::string s) { return v(s); };
  EXPECT_EQ(check(tool::integer_in(1, 16), "8"), "");
  EXPECT_EQ(check(tool::integer_in(1, 16), "+8"), "");
  EXPECT_EQ(check(tool::integer_in(1, 16), "abc"), "'abc' is not an integer (expects 1 to 16)");
  EXPECT_EQ(check(tool::integer_in(1, 16), "8x"), "'8x' is not an integer (expects 1 to 16)");
  EXPECT_EQ(check(tool::integer_in(1, 16), "2.5"), "'2.5' is not an integer (expects 1 to 16)");
  EXPECT_EQ(check(tool::integer_in(1, 16), "0"), "0 is out of range (expects 1 to 16)");
  EXPECT_EQ(check(tool::integer_in(1, 16), "99999999999999999999"),
            "99999999999999999999 is out of range (expects 1 to 16)");
  EXPECT_EQ(check(tool::number_in(1e-4, 0.1), "1e-3"), "");
  EXPECT_EQ(check(tool::number_in(1e-4, 0.1), "small"), "'small' is not a number (expects 0.0001 to 0.1)");
  EXPECT_EQ(check(tool::number_between(0, 1), "1"), "1 is out of range (expects a number strictly between 0 and 1)");
  EXPECT_EQ(check(tool::number_between(0, 1), "0.5"), "");
}

TEST(CommandLine, ShellCommandQuotesWhatAShellWouldSplit) {
  const char* argv[] = {"prtbake", "vertex", "my mesh.obj", "--env=a.exr", "it's", ""};
  EXPECT_EQ(tool::shell_command(6, argv), "prtbake vertex 'my mesh.obj' --env=a.exr 'it'\\''s' ''");
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
