#include "tool_main.h"

#include <bake/error.h>
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

int run_tool(const char* tool, int (*body)(int, char**), int argc, char** argv) {
  try {
    return body(argc, argv);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "%s: %s (try '%s --help')\n", tool, e.what(), tool);
    return kExitUsage;
  } catch (const bake::InputError& e) {
    std::fprintf(stderr, "%s: error: %s\n", tool, e.what());
    return kExitBadInput;
  } catch (const formats::FormatError& e) {
    std::fprintf(stderr, "%s: error: %s\n", tool, e.what());
    return kExitBadInput;
  } catch (const bake::Cancelled&) {
    std::fprintf(stderr, "%s: cancelled; nothing was written\n", tool);
    return kExitCancelled;
  } catch (const bake::SystemError& e) {
    std::fprintf(stderr, "%s: system error: %s\n", tool, e.what());
    return kExitSystem;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "%s: system error: out of memory\n", tool);
    return kExitSystem;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: internal error: %s\n", tool, e.what());
    return kExitInternal;
  } catch (...) {
    std::fprintf(stderr, "%s: internal error: unknown exception\n", tool);
    return kExitInternal;
  }
}

} // namespace prt::tool
