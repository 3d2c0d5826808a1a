// check.h (private to prtshade) — always-on argument checks of the shading entry points. A broken
// precondition throws std::invalid_argument "prtshade: <function>: <problem>"; the C API turns it
// into PRT_ERROR_INVALID_ARGUMENT with the same message.
#pragma once

#include <stdexcept>
#include <string>

namespace prt::shade::detail {

[[noreturn]] inline void argument_error(const char* function, const std::string& problem) {
  throw std::invalid_argument(std::string("prtshade: ") + function + ": " + problem);
}

} // namespace prt::shade::detail

#define PRT_SHADE_REQUIRE(cond, problem)                                                         \
  do {                                                                                           \
    if (!(cond)) ::prt::shade::detail::argument_error(__func__, (problem));                      \
  } while (0)
