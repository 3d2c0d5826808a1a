#include "tool_main.h"

#include <bake/core/error.h>
#include <formats/prtfile.h>

#include <csignal>
#include <cstdio>
#include <exception>
#include <new>

namespace prt::tool {

namespace {
bake::CancelToken g_interrupt;

extern "C" void on_sigint(int) {
  if (g_interrupt.requested()) {  // a second Ctrl-C: stop now
    std::signal(SIGINT, SIG_DFL);
    std::raise(SIGINT);
    return;
  }
  g_interrupt.request();
}
} // namespace

const bake::CancelToken& interrupt_token() { return g_interrupt; }

void install_interrupt_handler() { std::signal(SIGINT, on_sigint); }

namespace {
// One stderr line "<tool>: <kind><what>" and the exit code that goes with it.
int fail(const char* tool, const char* kind, const char* what, int code) {
  std::fprintf(stderr, "%s: %s%s\n", tool, kind, what);
  return code;
}
} // namespace

int run_tool(const char* tool, int (*body)(int, char**), int argc, char** argv) {
  try {
    return body(argc, argv);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "%s: %s (try '%s --help')\n", tool, e.what(), e.help().empty() ? tool : e.help().c_str());
    return kExitUsage;
  } catch (const bake::InputError& e) {
    return fail(tool, "error: ", e.what(), kExitBadInput);
  } catch (const formats::FormatError& e) {
    return fail(tool, "error: ", e.what(), kExitBadInput);
  } catch (const CancelledKeeping& e) {
    return fail(tool, "cancelled; ", e.what(), kExitCancelled);
  } catch (const bake::Cancelled&) {
    return fail(tool, "cancelled; nothing was written", "", kExitCancelled);
  } catch (const bake::SystemError& e) {
    return fail(tool, "system error: ", e.what(), kExitSystem);
  } catch (const std::bad_alloc&) {
    return fail(tool, "system error: ", "out of memory", kExitSystem);
  } catch (const std::exception& e) {
    return fail(tool, "internal error: ", e.what(), kExitInternal);
  } catch (...) {
    return fail(tool, "internal error: ", "unknown exception", kExitInternal);
  }
}

} // namespace prt::tool
