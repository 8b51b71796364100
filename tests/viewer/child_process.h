// Child processes for the end-to-end viewer tests: the real server (kept
// running, its port read from its first stdout line) and the real client
// (run to completion with a deadline).
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace meshstream::client::testing {

using namespace std::chrono_literals;

class ChildProcess {
 public:
  ChildProcess() = default;
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  ~ChildProcess() { kill_now(); }

  // Starts `args` (args[0] is the binary path); stdout is readable through
  // read_line, stderr goes to `stderr_path`. False when fork/pipe fail.
  bool start(const std::vector<std::string>& args, const std::string& stderr_path) {
    int out[2];
    if (::pipe(out) != 0) return false;
    pid_ = ::fork();
    if (pid_ < 0) return false;
    if (pid_ == 0) {
      ::dup2(out[1], 1);
      int err = ::open(stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (err >= 0) ::dup2(err, 2);
      ::close(out[0]);
      ::close(out[1]);
      // In sanitizer builds the children render with Mesa too (see
      // leak_check_off_test.cpp): their exit code must not be LSan's.
      std::string asan = ::getenv("ASAN_OPTIONS") ? ::getenv("ASAN_OPTIONS") : "";
      asan += (asan.empty() ? "" : ":") + std::string("detect_leaks=0");
      ::setenv("ASAN_OPTIONS", asan.c_str(), 1);
      std::vector<std::string> copy = args;
      std::vector<char*> argv;
      for (auto& a : copy) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    ::close(out[1]);
    stdout_fd_ = out[0];
    return true;
  }

  // One stdout line (without '\n'), nullopt at end of output or timeout.
  std::optional<std::string> read_line(std::chrono::milliseconds timeout) {
    auto deadline = std::chrono::steady_clock::now() + timeout;
    std::string line;
    while (std::chrono::steady_clock::now() < deadline) {
      pollfd p{stdout_fd_, POLLIN, 0};
      if (::poll(&p, 1, 50) <= 0) continue;
      char c;
      if (::read(stdout_fd_, &c, 1) != 1) return std::nullopt;
      if (c == '\n') return line;
      line += c;
    }
    return std::nullopt;
  }

  // Drains stdout and waits for the exit: the exit code (-signal when
  // killed), nullopt on timeout (the process is then killed).
  std::optional<int> wait(std::chrono::milliseconds timeout) {
    auto deadline = std::chrono::steady_clock::now() + timeout;
    while (pid_ > 0 && std::chrono::steady_clock::now() < deadline) {
      char buffer[4096];
      pollfd p{stdout_fd_, POLLIN, 0};
      if (stdout_fd_ >= 0 && ::poll(&p, 1, 20) > 0) {
        if (::read(stdout_fd_, buffer, sizeof buffer) <= 0) {
          ::close(stdout_fd_);
          stdout_fd_ = -1;
        }
      } else if (stdout_fd_ < 0) {
        std::this_thread::sleep_for(10ms);
      }
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
      }
    }
    kill_now();
    return std::nullopt;
  }

  void kill_now() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      int status = 0;
      ::waitpid(pid_, &status, 0);
      pid_ = -1;
    }
    if (stdout_fd_ >= 0) ::close(stdout_fd_);
    stdout_fd_ = -1;
  }

 private:
  pid_t pid_ = -1;
  int stdout_fd_ = -1;
};

}  // namespace meshstream::client::testing
