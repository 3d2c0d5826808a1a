// tests/fuzz/fuzz_common.cpp — the scratch directory and the finding report (fuzz_common.h).
#include "fuzz_common.h"

#include <cxxabi.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <typeinfo>

namespace fs = std::filesystem;

namespace prt::fuzz {

namespace {

fs::path scratch_base() {
  if (const char* tmp = std::getenv("TMPDIR"); tmp && *tmp) return tmp;
  std::error_code ec;
  if (fs::is_directory("/dev/shm", ec)) return "/dev/shm";
  return "/tmp";
}

void remove_scratch() {
  std::error_code ec;
  fs::remove_all(scratch_dir(), ec);
}

// Scratch directories of dead processes: a finding aborts and a timeout exits without running
// atexit, so each left its "prt-fuzz.<pid>" behind (30 after one fork-mode campaign).
void remove_stale_scratch(const fs::path& base) {
  std::error_code ec;
  for (fs::directory_iterator it(base, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind("prt-fuzz.", 0) != 0) continue;
    char* stop = nullptr;
    const long pid = std::strtol(name.c_str() + 9, &stop, 10);
    if (pid <= 0 || *stop != '\0' || pid == long(::getpid())) continue;
    if (::kill(pid_t(pid), 0) != 0 && errno == ESRCH) {
      std::error_code rm;
      fs::remove_all(it->path(), rm);
    }
  }
}

std::string type_name(const std::exception& e) {
  int status = 0;
  std::unique_ptr<char, void (*)(void*)> name(abi::__cxa_demangle(typeid(e).name(), nullptr, nullptr, &status), std::free);
  return status == 0 && name ? name.get() : typeid(e).name();
}

} // namespace

const fs::path& scratch_dir() {
  static const fs::path dir = [] {
    remove_stale_scratch(scratch_base());
    const fs::path d = scratch_base() / ("prt-fuzz." + std::to_string(::getpid()));
    std::error_code ec;
    fs::create_directories(d, ec);
    if (ec) {
      std::fprintf(stderr, "fuzz: cannot create %s: %s\n", d.c_str(), ec.message().c_str());
      std::abort();
    }
    std::atexit(remove_scratch);
    return d;
  }();
  return dir;
}

fs::path write_input(const std::string& name, std::string_view bytes) {
  const fs::path path = scratch_dir() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) {
    std::fprintf(stderr, "fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
  return path;
}

void finding(const char* what, const std::exception* e) {
  if (e) std::fprintf(stderr, "FUZZ FINDING: %s: %s: %s\n", what, type_name(*e).c_str(), e->what());
  else std::fprintf(stderr, "FUZZ FINDING: %s\n", what);
  std::fflush(stderr);
  std::abort();
}

void expected_error(const std::exception& e) {
  static const bool verbose = std::getenv("PRT_FUZZ_VERBOSE") != nullptr;
  if (verbose) std::fprintf(stderr, "expected: %s: %s\n", type_name(e).c_str(), e.what());
}

} // namespace prt::fuzz
