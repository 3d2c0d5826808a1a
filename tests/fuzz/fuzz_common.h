// tests/fuzz/fuzz_common.h — what every libFuzzer target shares (docs/RELIABILITY.md "Fuzzing").
//
// Contract of a target: LLVMFuzzerTestOneInput hands the bytes to one reader of untrusted input
// through guarded<Expected...>(body). The reader's documented errors (Expected: bake::InputError,
// formats::FormatError) are the right answer to a bad file and are swallowed; ANY other exception
// leaving the reader — std::bad_alloc (memory must stay bounded by the input's size),
// bake::ContractError (a broken precondition: a bug), bake::SystemError, anything else — is a
// finding: it is printed and the process aborts, so libFuzzer records the input. Crashes, leaks,
// sanitizer reports, timeouts and allocations over -malloc_limit_mb are libFuzzer's own findings.
//
// Readers that only take a path get the bytes as a file in this process's own scratch directory
// ($TMPDIR, else /dev/shm, else /tmp: "prt-fuzz.<pid>"), removed when the process exits (and, when
// the next one starts, if the process died without exiting); the
// same name is reused for every input.
#pragma once

#include <cstddef>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <string>
#include <string_view>

namespace prt::fuzz {

const std::filesystem::path& scratch_dir();
// `bytes` written to scratch_dir() / name (replacing it); returns the path. Aborts if it cannot
// (the machine, not the input: not a reader's finding, but a run that tests nothing).
std::filesystem::path write_input(const std::string& name, std::string_view bytes);
inline std::string_view as_bytes(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Prints "<what>: <exception type>: <message>" to stderr and aborts.
[[noreturn]] void finding(const char* what, const std::exception* e);
// With PRT_FUZZ_VERBOSE set in the environment, the expected errors are printed too (triage:
// `PRT_FUZZ_VERBOSE=1 fuzz_obj file.obj` says what the reader answered).
void expected_error(const std::exception& e);

namespace detail {
template <class First, class... Rest, class Body> void catch_expected(Body& body) {
  try {
    if constexpr (sizeof...(Rest) == 0) body();
    else catch_expected<Rest...>(body);
  } catch (const First& e) {
    expected_error(e);
  }
}
} // namespace detail

// Runs `body`: Expected exceptions are the reader's documented answer; anything else is a finding.
template <class... Expected, class Body> int guarded(Body&& body) {
  try {
    if constexpr (sizeof...(Expected) == 0) body();
    else detail::catch_expected<Expected...>(body);
  } catch (const std::exception& e) {
    finding("unexpected exception", &e);
  } catch (...) {
    finding("unexpected exception of a non-std type", nullptr);
  }
  return 0;
}

} // namespace prt::fuzz
