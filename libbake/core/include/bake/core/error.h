// bake/core/error.h — the three kinds of failure in libbake (after Filament's utils/Panic.h and
// pbrt's util/error.h); the tools map each to its own exit code (tools/common/tool_main.h,
// docs/ARCHITECTURE.md §6):
//   * InputError: the user's input is bad (a mesh, an EXR, a scene file, a value in it). what() is
//     one line that names the file and the defect: "<file>: <what is wrong>". Exit 1. libbake's
//     messages name files, keys and values, never a tool's command-line flags.
//   * SystemError: the machine failed us, not the input: the Embree device could not be created,
//     memory ran out, a system call failed. Exit 3.
//   * ContractError / PRT_CHECK: a bug in prtbake (a broken precondition). Always on. Exit 4,
//     "internal error".
// Exceptions never leave a library unconverted: third-party exceptions (OpenEXR's Iex, Embree
// error codes) are caught at the boundary and rethrown as one of these.
#pragma once

#include <new>
#include <sstream>
#include <stdexcept>
#include <string>

namespace prt::bake {

class InputError : public std::runtime_error {
public:
  InputError(const std::string& file, const std::string& defect)
      : std::runtime_error(file.empty() ? defect : file + ": " + defect), file_(file), defect_(defect) {}
  const std::string& file() const noexcept { return file_; }
  const std::string& defect() const noexcept { return defect_; }

private:
  std::string file_, defect_;
};

class SystemError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// Runs `read` (which reads `file`) and turns running out of memory into a SystemError naming the
// file: "<file>: out of memory while reading the file". The readers bound what a file can make
// them allocate (docs/RELIABILITY.md), so this is a machine short of memory for a large input.
template <class Read>
auto reading_file(const std::string& file, Read&& read) -> decltype(read()) {
  try {
    return read();
  } catch (const std::bad_alloc&) {
    throw SystemError(file + ": out of memory while reading the file");
  }
}

class ContractError : public std::logic_error {
public:
  using std::logic_error::logic_error;
};

} // namespace prt::bake

// Always-on check that prints the failed condition and its location.
#define PRT_CHECK(cond)                                                                          \
  do {                                                                                           \
    if (!(cond)) {                                                                               \
      std::ostringstream prt_check_os_;                                                          \
      prt_check_os_ << __FILE__ << ":" << __LINE__ << ": check failed: " #cond;                  \
      throw ::prt::bake::ContractError(prt_check_os_.str());                                     \
    }                                                                                            \
  } while (0)
// Always-on comparison check that prints both operands.
#define PRT_CHECK_OP(a, op, b)                                                                   \
  do {                                                                                           \
    const auto& prt_a_ = (a);                                                                    \
    const auto& prt_b_ = (b);                                                                    \
    if (!(prt_a_ op prt_b_)) {                                                                   \
      std::ostringstream prt_check_os_;                                                          \
      prt_check_os_ << __FILE__ << ":" << __LINE__ << ": check failed: " #a " " #op " " #b       \
                    << " (" << prt_a_ << " vs " << prt_b_ << ")";                                \
      throw ::prt::bake::ContractError(prt_check_os_.str());                                     \
    }                                                                                            \
  } while (0)
