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
//   130  cancelled (Ctrl-C / SIGINT): the bake stopped and wrote nothing
#pragma once

#include <bake/progress.h>

#include <stdexcept>
#include <string>

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
    "  130  cancelled with Ctrl-C: nothing was written\n";

// A command-line mistake found after parsing (a missing output, options that do not go together).
class UsageError : public std::runtime_error {
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
