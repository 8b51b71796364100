// Real web servers for the HTTP stream path's tests and bench, started and
// stopped by them on a free loopback port: nginx in the foreground as the
// current user with docs/nginx.conf (the configuration docs/deploy.md shows),
// and Python's http.server (no Range support). Each start() returns "" when
// the server accepts connections, else why not ("... is not installed" for
// a visible skip).
#pragma once

#include <cstdlib>
#include <regex>
#include <string>

#include "tests/client/client_harness.h"

namespace meshstream::clienttest {

// An executable on PATH (or the usual sbin folders), "" when there is none.
inline std::string find_program(const std::string& name) {
  std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  path += ":/usr/sbin:/sbin:/usr/local/sbin";
  size_t at = 0;
  while (at <= path.size()) {
    const size_t colon = std::min(path.find(':', at), path.size());
    const fs::path candidate = fs::path(path.substr(at, colon - at)) / name;
    if (colon > at && ::access(candidate.c_str(), X_OK) == 0) return candidate.string();
    at = colon + 1;
  }
  return "";
}

inline bool accepting(uint16_t port) {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(port);
  const bool ok = ::connect(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  ::close(s);
  return ok;
}

inline bool wait_accepting(uint16_t port, Child& child) {
  const auto deadline = Clock::now() + 15s;
  while (Clock::now() < deadline) {
    if (accepting(port)) return true;
    if (child.wait(20ms)) return false;  // it exited
  }
  return false;
}

// nginx as the current user, in the foreground, with docs/nginx.conf.
class Nginx {
 public:
  // "" when it runs, else why not.
  std::string start(const std::string& root, const std::string& run_dir) {
    const std::string bin = find_program("nginx");
    if (bin.empty()) return "nginx is not installed";
    fs::create_directories(run_dir);
    port_ = free_port();
    std::string conf = read_text(std::string(MESHSTREAM_SOURCE_DIR) + "/docs/nginx.conf");
    conf = std::regex_replace(conf, std::regex("@LISTEN@"), "127.0.0.1:" + std::to_string(port_));
    conf = std::regex_replace(conf, std::regex("@ROOT@"), root);
    conf = std::regex_replace(conf, std::regex("@RUN_DIR@"), run_dir);
    const std::string conf_file = run_dir + "/nginx.conf";
    std::ofstream(conf_file) << conf;
    log_ = run_dir + "/error.log";
    access_ = run_dir + "/access.log";
    if (!child_.start({bin, "-p", run_dir, "-e", log_, "-c", conf_file}, run_dir + "/nginx.out",
                      run_dir + "/nginx.err"))
      return "cannot start nginx";
    if (!wait_accepting(port_, child_)) {
      return "nginx did not start: " + read_text(run_dir + "/nginx.err") + read_text(log_);
    }
    return "";
  }
  ~Nginx() {
    child_.signal(SIGQUIT);  // graceful stop
    if (!child_.wait(5s)) child_.kill_now();
  }
  uint16_t port() const { return port_; }
  std::string access_log() const { return read_text(access_); }

 private:
  Child child_;
  uint16_t port_ = 0;
  std::string log_, access_;
};

// python3 -m http.server: HTTP/1.0, no Range support.
class PythonHttp {
 public:
  std::string start(const std::string& root, const std::string& run_dir) {
    const std::string bin = find_program("python3");
    if (bin.empty()) return "python3 is not installed";
    fs::create_directories(run_dir);
    port_ = free_port();
    err_ = run_dir + "/python.err";
    if (!child_.start({bin, "-m", "http.server", std::to_string(port_), "--bind", "127.0.0.1",
                       "--directory", root},
                      run_dir + "/python.out", err_))
      return "cannot start python3";
    if (!wait_accepting(port_, child_)) return "http.server did not start: " + read_text(err_);
    return "";
  }
  ~PythonHttp() {
    child_.signal(SIGTERM);
    if (!child_.wait(5s)) child_.kill_now();
  }
  uint16_t port() const { return port_; }
  std::string log() const { return read_text(err_); }

 private:
  Child child_;
  uint16_t port_ = 0;
  std::string err_;
};

}  // namespace meshstream::clienttest
