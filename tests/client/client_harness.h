// Harness for the client suite: runs the REAL binaries (meshstream-server,
// meshstream-client, meshstream) as child processes on loopback, reads their
// output and the meshes they write. No mocks.
#pragma once

#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "common/mesh/mesh.h"
#include "common/mesh/mesh_readers.h"

namespace meshstream::clienttest {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;
namespace fs = std::filesystem;

inline std::string server_bin() {
  return std::string(MESHSTREAM_BINARY_DIR) + "/server/meshstream-server";
}
inline std::string client_bin() {
  return std::string(MESHSTREAM_BINARY_DIR) + "/client/meshstream-client";
}
inline std::string tool_bin() { return std::string(MESHSTREAM_BINARY_DIR) + "/tools/meshstream"; }

// A fresh directory under the system temp dir, removed at the end.
class TempDir {
 public:
  TempDir() {
    std::string tmpl = (fs::temp_directory_path() / "ms-client-test-XXXXXX").string();
    path_ = ::mkdtemp(tmpl.data());
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string operator/(const std::string& name) const { return (fs::path(path_) / name).string(); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// A child process with stdout and stderr redirected to files.
class Child {
 public:
  Child() = default;
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child() { kill_now(); }

  bool start(const std::vector<std::string>& argv, const std::string& out, const std::string& err) {
    pid_ = ::fork();
    if (pid_ < 0) return false;
    if (pid_ == 0) {
      const int o = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int e = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (o >= 0) ::dup2(o, 1);
      if (e >= 0) ::dup2(e, 2);
      std::vector<std::string> copy = argv;
      std::vector<char*> args;
      for (auto& a : copy) args.push_back(a.data());
      args.push_back(nullptr);
      ::execv(args[0], args.data());
      ::_exit(127);
    }
    return true;
  }
  // Exit status (or -signal); nullopt on timeout (the child keeps running).
  std::optional<int> wait(std::chrono::milliseconds timeout) {
    const auto deadline = Clock::now() + timeout;
    while (pid_ > 0) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
      }
      if (Clock::now() >= deadline) return std::nullopt;
      std::this_thread::sleep_for(5ms);
    }
    return std::nullopt;
  }
  void signal(int sig) {
    if (pid_ > 0) ::kill(pid_, sig);
  }
  void kill_now() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      int status;
      ::waitpid(pid_, &status, 0);
      pid_ = -1;
    }
  }
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
};

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs a command to completion (60 s at most); its exit status.
inline int run(const std::vector<std::string>& argv, const std::string& out,
               const std::string& err) {
  Child child;
  if (!child.start(argv, out, err)) return -1000;
  auto status = child.wait(60s);
  return status ? *status : -1001;
}

// The client tests' model: the procedural demo mesh at 20k triangles,
// written by the offline tool to DIR/demo.ply and encoded by it to
// DIR/models/demo.hcs, the peer the client is checked against. Empty when
// both commands succeeded, else what failed and its stderr.
// Suites that do not test the encoder's ASA guidance pass
// with_asa_guidance = false: measuring it makes the encode about four times
// slower, and SetUpTestSuite runs once per test process.
inline std::string make_demo_model(const std::string& dir, bool with_asa_guidance = true) {
  std::filesystem::create_directories(dir + "/models");
  if (run({tool_bin(), "generate", "demo", "--size", "20000", "-o", dir + "/demo.ply"},
          dir + "/gen.out", dir + "/gen.err") != 0) {
    return "generate: " + read_text(dir + "/gen.err");
  }
  std::vector<std::string> encode{tool_bin(), "encode", dir + "/demo.ply", "-o",
                                  dir + "/models/demo.hcs"};
  if (!with_asa_guidance) encode.push_back("--no-asa-guidance");
  if (run(encode, dir + "/enc.out", dir + "/enc.err") != 0) {
    return "encode: " + read_text(dir + "/enc.err");
  }
  return "";
}

// A port nobody listens on right now (bind to 0, read it, close).
inline uint16_t free_port() {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  ::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  ::getsockname(s, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(s);
  return ntohs(a.sin_port);
}

// meshstream-server on loopback; port 0 = any (read from its stdout line
// "listening on HOST:PORT").
class Server {
 public:
  bool start(const std::vector<std::string>& args, const std::string& dir, uint16_t port = 0) {
    out_ = dir + "/server.out";
    err_ = dir + "/server.err";
    // A previous server's line must not be mistaken for this one's.
    std::error_code ignored;
    fs::remove(out_, ignored);
    std::vector<std::string> argv{server_bin(), "--listen", "127.0.0.1:" + std::to_string(port)};
    argv.insert(argv.end(), args.begin(), args.end());
    if (!child_.start(argv, out_, err_)) return false;
    const auto deadline = Clock::now() + 20s;
    while (Clock::now() < deadline) {
      const std::string text = read_text(out_);
      const auto nl = text.find('\n');
      if (nl != std::string::npos) {
        const std::string line = text.substr(0, nl);
        const auto colon = line.rfind(':');
        if (line.rfind("listening on ", 0) != 0 || colon == std::string::npos) return false;
        port_ = static_cast<uint16_t>(std::stoi(line.substr(colon + 1)));
        // The server encodes in the background while it serves: wait until
        // the models it found at start are ready (or failed).
        while (read_text(err_).find("initial models done") == std::string::npos) {
          if (Clock::now() >= deadline + 100s || child_.wait(10ms)) return false;
        }
        return true;
      }
      if (child_.wait(10ms)) return false;  // exited
    }
    return false;
  }
  uint16_t port() const { return port_; }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  std::string log() const { return read_text(err_); }
  void kill_hard() { child_.kill_now(); }
  std::optional<int> stop() {
    child_.signal(SIGTERM);
    return child_.wait(10s);
  }

 private:
  Child child_;
  std::string out_, err_;
  uint16_t port_ = 0;
};

// The JSON event lines of a client run.
inline std::vector<nlohmann::json> parse_events(const std::string& text) {
  std::vector<nlohmann::json> events;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    events.push_back(nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false));
  }
  return events;
}

inline std::vector<nlohmann::json> of_kind(const std::vector<nlohmann::json>& events,
                                           const std::string& kind) {
  std::vector<nlohmann::json> out;
  for (const auto& e : events) {
    if (e.is_object() && e.value("event", "") == kind) out.push_back(e);
  }
  return out;
}

inline Mesh load_ply(const std::string& path) {
  auto raw = read_ply(path);
  if (!raw) return Mesh{};
  return std::move(raw->mesh);
}

// The mesh as a sorted list of triangles given by their corner positions
// (bit patterns), each rotated to start at its smallest corner: equal for
// two meshes with the same triangles at the same positions, whatever order
// their vertices and faces come in.
using CornerKey = std::array<uint32_t, 3>;
using TriangleKey = std::array<CornerKey, 3>;
inline std::vector<TriangleKey> canonical_triangles(const Mesh& m) {
  auto key = [&](uint32_t v) {
    CornerKey k;
    std::memcpy(k.data(), &m.positions[v], sizeof(Vec3f));
    return k;
  };
  std::vector<TriangleKey> out;
  out.reserve(m.triangles.size());
  for (const Triangle& t : m.triangles) {
    TriangleKey k{key(t[0]), key(t[1]), key(t[2])};
    const size_t first = std::min_element(k.begin(), k.end()) - k.begin();
    std::rotate(k.begin(), k.begin() + first, k.end());
    out.push_back(k);
  }
  std::sort(out.begin(), out.end());
  return out;
}

inline bool same_geometry(const Mesh& a, const Mesh& b) {
  return a.vertex_count() == b.vertex_count() && a.face_count() == b.face_count() &&
         canonical_triangles(a) == canonical_triangles(b);
}

}  // namespace meshstream::clienttest
