// tools/common/tool_main.h — how every prt tool ends: one line on stderr and an exit code that
// says whose fault it was (docs/ARCHITECTURE.md §6; each tool's --help lists them).
//
//   0    success
//   1    bad input: a file or a value in it (bake::InputError, formats::FormatError); the line
//        names the file and the problem; no output file is left behind
//   2    bad command line (UsageError, and the command-line parser's own errors)
//   3    the machine failed: out of memory, no Embree device, a failed system call
//        (bake::SystemError, std::bad_alloc)
//   4    internal error: a broken invariant inside prt (a bug; please report it)
//   130  cancelled (Ctrl-C / SIGINT): the bake stopped and wrote nothing (CancelledKeeping: a
//        sharded or resumable bake keeps its committed chunks and the line says where and how
//        to resume)
#pragma once

#include <bake/core/progress.h>

#include <stdexcept>
#include <string>
#include <utility>

namespace prt::tool {

enum ExitCode : int {
  kExitOk = 0,
  kExitBadInput = 1,
  kExitUsage = 2,
  kExitSystem = 3,
  kExitInternal = 4,
  kExitCancelled = 130,
};

// The EXIT STATUS section every tool's --help ends with.
inline constexpr const char* kExitStatusHelp =
    "EXIT STATUS\n"
    "  0    success\n"
    "  1    bad input: one line on stderr names the file and the problem; no output is left behind\n"
    "  2    bad command line\n"
    "  3    the machine failed: out of memory, no Embree device, a failed system call\n"
    "  4    internal error: a bug in the prtbake toolkit (please report it with the command line)\n"
    "  130  cancelled with Ctrl-C: nothing was written (a --resume or --shard bake keeps its\n"
    "       committed chunks; the message says where and the command that resumes)\n";

// The version every tool answers --version with ("prtbake 0.1.0", "prtdump 0.1.0").
inline constexpr const char* kToolkitVersion = "0.1.0";

// A command-line mistake (a missing output, options that do not go together), found before any
// work. `help`: the command whose --help explains (default: the tool's own).
class UsageError : public std::runtime_error {
public:
  explicit UsageError(const std::string& what, std::string help = "")
      : std::runtime_error(what), help_(std::move(help)) {}
  const std::string& help() const noexcept { return help_; }

private:
  std::string help_;
};

// A cancelled bake that keeps what it committed (chunks of a --resume or --shard bake): what()
// says what is kept, where, and the command that resumes. Exit 130 like any cancellation.
class CancelledKeeping : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// The token SIGINT requests; install_interrupt_handler() arms it (the first Ctrl-C cancels
// cleanly, a second one kills the process at once).
const bake::CancelToken& interrupt_token();
void install_interrupt_handler();

// Runs `body`, maps what it throws to one stderr line "<tool>: ..." and an ExitCode.
int run_tool(const char* tool, int (*body)(int, char**), int argc, char** argv);

} // namespace prt::tool
