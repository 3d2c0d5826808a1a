// Runs a tool binary the way a user does (through the shell) and captures what it printed.
#pragma once

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <poll.h>
#include <string>
#include <string_view>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

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

// A tool started in the background (no shell), its stdout discarded and its stderr on a pipe, so a
// test can wait for something it prints and then signal it (e.g. SIGINT in the middle of a bake).
class BackgroundTool {
public:
  BackgroundTool(const std::string& binary, const std::vector<std::string>& args) {
    int fds[2];
    if (pipe(fds) != 0) return;
    std::vector<char*> argv{const_cast<char*>(binary.c_str())};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    pid_ = fork();
    if (pid_ == 0) {  // the child: only async-signal-safe calls until exec
      const int null = open("/dev/null", O_WRONLY);
      dup2(null, STDOUT_FILENO);
      dup2(fds[1], STDERR_FILENO);
      close(fds[0]);
      close(fds[1]);
      ::signal(SIGINT, SIG_DFL);
      execv(binary.c_str(), argv.data());
      _exit(127);
    }
    close(fds[1]);
    err_fd_ = fds[0];
  }
  ~BackgroundTool() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    if (err_fd_ >= 0) close(err_fd_);
  }
  BackgroundTool(const BackgroundTool&) = delete;
  BackgroundTool& operator=(const BackgroundTool&) = delete;

  bool started() const { return pid_ > 0 && err_fd_ >= 0; }
  const std::string& err() const { return err_; }

  // Reads stderr until it contains `needle`, it closes, or `timeout` passes; true if found.
  bool wait_for(std::string_view needle, std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (err_.find(needle) == std::string::npos) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now());
      if (left.count() <= 0 || !read_some(int(left.count()))) return false;
    }
    return true;
  }
  void send(int sig) const { kill(pid_, sig); }
  // Reads the rest of stderr and reaps the tool: its exit status (-1 if a signal killed it).
  int wait() {
    while (read_some(-1)) {
    }
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

private:
  // One read from stderr (waiting up to timeout_ms, -1: forever); false at its end or timeout.
  bool read_some(int timeout_ms) {
    pollfd p{err_fd_, POLLIN, 0};
    if (poll(&p, 1, timeout_ms) <= 0) return false;
    char buf[4096];
    const ssize_t n = read(err_fd_, buf, sizeof buf);
    if (n <= 0) return false;
    err_.append(buf, size_t(n));
    return true;
  }

  pid_t pid_ = -1;
  int err_fd_ = -1;
  std::string err_;
};

} // namespace prt::testing
