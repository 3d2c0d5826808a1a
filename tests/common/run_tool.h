// Runs a tool binary the way a user does (through the shell) and captures what it printed.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace prt::testing {

// A whole file's bytes (empty if it does not exist).
inline std::string read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary | std::ios::ate);
  if (!in) return {};
  std::string s(static_cast<std::size_t>(std::max<std::streamoff>(in.tellg(), 0)), '\0');
  in.seekg(0);
  in.read(s.data(), static_cast<std::streamsize>(s.size()));
  return s;
}

struct ToolRun {
  int code = -1;  // exit status (-1: killed by a signal)
  std::string out, err;
};

// `binary args` with stdout and stderr captured in files under `capture_dir` (tagged with the pid
// and a counter: ctest runs cases in parallel processes). `env` is prefixed (e.g. "A=1").
inline ToolRun run_tool(const std::string& binary, const std::string& args, const std::filesystem::path& capture_dir,
                        const std::string& env = "") {
  static int counter = 0;
  std::filesystem::create_directories(capture_dir);
  const std::string tag = std::to_string(getpid()) + "." + std::to_string(counter++);
  const std::filesystem::path o = capture_dir / ("stdout." + tag), e = capture_dir / ("stderr." + tag);
  const std::string cmd = env + " '" + binary + "' " + args + " > '" + o.string() + "' 2> '" + e.string() + "'";
  const int status = std::system(cmd.c_str());
  ToolRun r{WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_bytes(o), read_bytes(e)};
  std::filesystem::remove(o);
  std::filesystem::remove(e);
  return r;
}

} // namespace prt::testing
