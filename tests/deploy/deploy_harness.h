// Harness of the deployment suite (and bench/failover_bench): a fleet of
// real meshstream-server processes sharing one cache folder, HAProxy in
// front of them with the configuration of docs/deploy.md (read from there,
// so the page and the tests cannot drift), and many real meshstream-client
// processes at once.
#pragma once

#include <cstdlib>
#include <memory>
#include <regex>

#include "tests/client/client_harness.h"
#include "tests/net/net_harness.h"
#include "tests/net/prometheus_text.h"

namespace meshstream::deploytest {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using clienttest::Child;
using clienttest::read_text;
using Clock = std::chrono::steady_clock;

inline std::string haproxy_binary() {
  for (const char* path : {"/usr/sbin/haproxy", "/usr/bin/haproxy", "/usr/local/sbin/haproxy"}) {
    if (fs::exists(path)) return path;
  }
  return "";
}

// The first ```haproxy block of docs/deploy.md: the configuration the page
// shows is the one that runs. "" when the page has none.
inline std::string haproxy_config_from_docs() {
  const std::string page = read_text(std::string(MESHSTREAM_SOURCE_DIR) + "/docs/deploy.md");
  const auto start = page.find("\n```haproxy\n");
  if (start == std::string::npos) return "";
  const auto body = start + std::string("\n```haproxy\n").size();
  const auto end = page.find("\n```\n", body);
  if (end == std::string::npos) return "";
  return page.substr(body, end - body + 1);
}

// Writes the models folder of the suite: `name`.ply, the procedural demo
// knot at `triangles` triangles. "" or the tool's error.
inline std::string make_model(const std::string& dir, const std::string& name, int triangles) {
  fs::create_directories(dir);
  const std::string ply = dir + "/" + name + ".ply";
  if (clienttest::run({clienttest::tool_bin(), "generate", "demo", "--size",
                       std::to_string(triangles), "-o", ply},
                      dir + "/../gen.out", dir + "/../gen.err") != 0) {
    return "generate: " + read_text(dir + "/../gen.err");
  }
  return "";
}

// One meshstream-server with --metrics on free ports.
struct FleetServer {
  nettest::ServerProcess process;
  uint16_t metrics_port = 0;
  std::string log_path;
  std::string address() const { return "127.0.0.1:" + std::to_string(process.port()); }
  nettest::PrometheusText scrape() const {
    return nettest::parse_prometheus(
        nettest::curl("http://127.0.0.1:" + std::to_string(metrics_port) + "/metrics").body);
  }
};

// Starts `n` servers at once (all encoding at the same time on a cold
// cache), each with `args` plus --metrics; false (and `problem`) when one
// does not come up.
inline bool start_fleet(std::vector<std::unique_ptr<FleetServer>>& fleet, size_t n,
                        const std::vector<std::string>& args, const std::string& log_dir,
                        std::string& problem) {
  for (size_t i = 0; i < n; ++i) fleet.push_back(std::make_unique<FleetServer>());
  std::vector<std::thread> starting;
  std::vector<std::string> problems(n);
  for (size_t i = 0; i < n; ++i) {
    starting.emplace_back([&, i] {
      FleetServer& s = *fleet[i];
      s.log_path = log_dir + "/server" + std::to_string(i + 1) + ".log";
      std::vector<std::string> all = args;
      all.insert(all.end(), {"--metrics", "127.0.0.1:0"});
      if (!s.process.start(all, s.log_path, 60s)) {
        problems[i] = "server " + std::to_string(i + 1) + " did not start: " + s.process.log();
        return;
      }
      s.metrics_port = s.process.read_metrics_port();
      if (s.metrics_port == 0)
        problems[i] = "server " + std::to_string(i + 1) + ": no metrics line";
    });
  }
  for (auto& t : starting) t.join();
  for (const std::string& p : problems) problem += p;
  return problem.empty();
}

// HAProxy in the foreground (-db) with the docs' configuration, the fleet's
// addresses in its environment; stopped (SIGTERM) by the destructor.
class Haproxy {
 public:
  ~Haproxy() { stop(); }
  bool start(const std::vector<std::unique_ptr<FleetServer>>& fleet, const std::string& dir,
             std::string& problem) {
    const std::string config = haproxy_config_from_docs();
    if (config.empty()) {
      problem = "docs/deploy.md has no ```haproxy block";
      return false;
    }
    config_path_ = dir + "/haproxy.cfg";
    std::ofstream(config_path_) << config;
    log_path_ = dir + "/haproxy.log";
    front_port_ = clienttest::free_port();
    std::vector<std::string> env{"MESHSTREAM_FRONT=127.0.0.1:" + std::to_string(front_port_)};
    for (size_t i = 0; i < fleet.size(); ++i) {
      const std::string n = std::to_string(i + 1);
      env.push_back("MESHSTREAM_S" + n + "=" + fleet[i]->address());
      env.push_back("MESHSTREAM_S" + n + "_METRICS=" + std::to_string(fleet[i]->metrics_port));
    }
    // Checked first (-c): a config HAProxy refuses is a clear failure.
    std::string check_cmd;
    for (const std::string& e : env) check_cmd += e + " ";
    check_cmd += haproxy_binary() + " -c -q -f " + config_path_ + " > " + log_path_ + " 2>&1";
    if (std::system(check_cmd.c_str()) != 0) {
      problem = "haproxy refuses the configuration of docs/deploy.md: " + read_text(log_path_);
      return false;
    }
    pid_ = ::fork();
    if (pid_ == 0) {
      for (const std::string& e : env) ::putenv(::strdup(e.c_str()));
      const int log = ::open(log_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (log >= 0) {
        ::dup2(log, 1);
        ::dup2(log, 2);
      }
      const std::string bin = haproxy_binary();
      ::execl(bin.c_str(), bin.c_str(), "-db", "-f", config_path_.c_str(), nullptr);
      ::_exit(127);
    }
    // Up when its frontend accepts a connection.
    const auto deadline = Clock::now() + 10s;
    while (Clock::now() < deadline) {
      nettest::TestClient probe;
      if (probe.connect(front_port_)) return true;
      std::this_thread::sleep_for(20ms);
    }
    problem = "haproxy did not listen on its frontend: " + read_text(log_path_);
    return false;
  }
  uint16_t front_port() const { return front_port_; }
  std::string front() const { return "127.0.0.1:" + std::to_string(front_port_); }
  std::string log() const { return read_text(log_path_); }
  void stop() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    int status;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
  }

 private:
  pid_t pid_ = -1;
  uint16_t front_port_ = 0;
  std::string config_path_, log_path_;
};

// One meshstream-client run: where it writes, and how it ended.
struct ClientRun {
  std::string dir;
  int exit_code = -1;
  std::string stderr_text;
  nlohmann::json done;    // its "done" event (null if none)
  double header_ms = -1;  // its "header" event's elapsed_ms: start to header + first chunk
};

// Starts `n` meshstream-client processes on `address` streaming `model`
// into dir/cNNN (--out, --json, --quiet, `extra`), `spacing` apart, and
// calls `after_started` once all are running; then waits up to `timeout`
// for every one (a client still running then is killed and counts as exit
// -1000). Processes, not threads: each is the program a user runs.
inline std::vector<ClientRun> run_clients(size_t n, const std::string& address,
                                          const std::string& model, const std::string& dir,
                                          const std::vector<std::string>& extra,
                                          std::chrono::microseconds spacing,
                                          const std::function<void()>& after_started,
                                          std::chrono::seconds timeout) {
  std::vector<ClientRun> runs(n);
  std::vector<std::unique_ptr<Child>> children;
  for (size_t i = 0; i < n; ++i) {
    char name[16];
    std::snprintf(name, sizeof name, "c%03zu", i);
    runs[i].dir = dir + "/" + name;
    std::vector<std::string> argv{
        clienttest::client_bin(), address, model, "--out", runs[i].dir, "--json", "--quiet"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    children.push_back(std::make_unique<Child>());
    children.back()->start(argv, runs[i].dir + ".out", runs[i].dir + ".err");
    if (spacing.count() > 0) std::this_thread::sleep_for(spacing);
  }
  if (after_started) after_started();
  const auto deadline = Clock::now() + timeout;
  for (size_t i = 0; i < n; ++i) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    const auto status = children[i]->wait(std::max(left, std::chrono::milliseconds(1)));
    runs[i].exit_code = status ? *status : -1000;
    runs[i].stderr_text = read_text(runs[i].dir + ".err");
    const auto events = clienttest::parse_events(read_text(runs[i].dir + ".out"));
    for (const auto& e : clienttest::of_kind(events, "done")) runs[i].done = e;
    for (const auto& e : clienttest::of_kind(events, "header")) {
      if (runs[i].header_ms < 0) runs[i].header_ms = e.value("elapsed_ms", -1.0);
    }
  }
  return runs;
}

}  // namespace meshstream::deploytest
