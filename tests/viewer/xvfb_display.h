// A private virtual X display (Xvfb) for window tests, started on a free
// display number and stopped when the object goes away. Tests skip visibly
// when Xvfb is not installed.
#pragma once

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

extern char** environ;

namespace meshstream::client::testing {

class XvfbDisplay {
 public:
  static std::string find_xvfb() {
    for (const char* candidate : {"/usr/bin/Xvfb", "/usr/local/bin/Xvfb"}) {
      if (::access(candidate, X_OK) == 0) return candidate;
    }
    return {};
  }

  // Starts Xvfb on the first display number in 90..189 with no lock file and
  // waits (up to 10 s) for its socket. Returns the display name (":93") or
  // empty on failure.
  std::string start() {
    std::string xvfb = find_xvfb();
    if (xvfb.empty()) return {};
    for (int n = 90 + static_cast<int>(::getpid() % 50); n < 190; ++n) {
      std::string lock = "/tmp/.X" + std::to_string(n) + "-lock";
      std::string socket = "/tmp/.X11-unix/X" + std::to_string(n);
      if (std::filesystem::exists(lock) || std::filesystem::exists(socket)) continue;
      std::string display = ":" + std::to_string(n);
      const char* argv[] = {xvfb.c_str(), display.c_str(), "-screen",  "0",    "1024x768x24",
                            "-nolisten",  "tcp",           "-noreset", nullptr};
      posix_spawn_file_actions_t actions;
      posix_spawn_file_actions_init(&actions);
      posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", 1 /*O_WRONLY*/, 0);
      posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", 1 /*O_WRONLY*/, 0);
      int rc =
          posix_spawn(&pid_, xvfb.c_str(), &actions, nullptr, const_cast<char**>(argv), environ);
      posix_spawn_file_actions_destroy(&actions);
      if (rc != 0) return {};
      auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (std::chrono::steady_clock::now() < deadline) {
        if (std::filesystem::exists(socket)) {
          display_ = display;
          return display_;
        }
        int status = 0;
        if (::waitpid(pid_, &status, WNOHANG) == pid_) {  // died: display taken after all
          pid_ = -1;
          break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      if (pid_ > 0) stop();
    }
    return {};
  }

  void stop() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      int status = 0;
      ::waitpid(pid_, &status, 0);
      pid_ = -1;
    }
  }

  ~XvfbDisplay() { stop(); }
  const std::string& display() const { return display_; }

 private:
  pid_t pid_ = -1;
  std::string display_;
};

}  // namespace meshstream::client::testing
