// Test harness for the network suite: runs the REAL meshstream-server binary
// as a child process on loopback and talks to it over real sockets with the
// shared framing (no mocks). Blocking POSIX sockets with poll() timeouts keep
// the tests simple and their failures readable.
#pragma once

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "proto/framing.h"

namespace meshstream::nettest {

namespace v1 = ::meshstream::v1;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

inline std::string server_binary() {
  return std::string(MESHSTREAM_BINARY_DIR) + "/server/meshstream-server";
}

inline std::vector<uint8_t> read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

inline void write_file(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

// A meshstream-server child process. Its stderr goes to `log_path`; the
// first stdout line "listening on HOST:PORT" gives the port.
class ServerProcess {
 public:
  ServerProcess() = default;
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;
  ~ServerProcess() { kill_now(); }

  // What start() waits for after the port: the models found at start all
  // ready or failed (the server's "initial models done" line), or only the
  // port (the server encodes in the background while it serves).
  enum class Wait { kInitialModels, kPort };

  // Starts the server with `args` (after the binary name, "--listen
  // 127.0.0.1:0" is added unless `args` has a --listen) and waits up to
  // `timeout` for its port and, by default, its initial models. False when
  // it did not come up (see log()).
  bool start(const std::vector<std::string>& args, const std::string& log_path,
             std::chrono::milliseconds timeout = 20s, Wait wait = Wait::kInitialModels) {
    log_path_ = log_path;
    int out[2];
    if (::pipe(out) != 0) return false;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(out[1], 1);
      const int err = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (err >= 0) ::dup2(err, 2);
      ::close(out[0]);
      ::close(out[1]);
      std::vector<std::string> all{server_binary()};
      if (std::find(args.begin(), args.end(), "--listen") == args.end()) {
        all.insert(all.end(), {"--listen", "127.0.0.1:0"});
      }
      all.insert(all.end(), args.begin(), args.end());
      std::vector<char*> argv;
      for (auto& a : all) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    ::close(out[1]);
    stdout_fd_ = out[0];
    const auto deadline = Clock::now() + timeout;
    const std::string line = read_stdout_line(timeout);
    const auto colon = line.rfind(':');
    if (line.rfind("listening on ", 0) != 0 || colon == std::string::npos) return false;
    port_ = static_cast<uint16_t>(std::stoi(line.substr(colon + 1)));
    if (wait == Wait::kPort) return true;
    return wait_log("initial models done",
                    std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()));
  }

  // The next line the server prints on stdout (after "listening on": with
  // --metrics, "metrics on HOST:PORT"); "" at its end or after `timeout`.
  std::string read_stdout_line(std::chrono::milliseconds timeout = 5s) {
    std::string line;
    const auto deadline = Clock::now() + timeout;
    while (Clock::now() < deadline) {
      pollfd p{stdout_fd_, POLLIN, 0};
      if (::poll(&p, 1, 50) <= 0) continue;
      char c;
      if (::read(stdout_fd_, &c, 1) != 1) return "";
      if (c == '\n') return line;
      line += c;
    }
    return "";
  }
  // The port of the "metrics on HOST:PORT" line (0 when it is not there).
  uint16_t read_metrics_port() {
    const std::string line = read_stdout_line();
    const auto colon = line.rfind(':');
    if (line.rfind("metrics on ", 0) != 0 || colon == std::string::npos) return 0;
    return static_cast<uint16_t>(std::stoi(line.substr(colon + 1)));
  }

  // Polls the log until it holds `text` (true) or `timeout` passes.
  bool wait_log(const std::string& text, std::chrono::milliseconds timeout) const {
    const auto deadline = Clock::now() + timeout;
    while (log().find(text) == std::string::npos) {
      if (Clock::now() >= deadline) return false;
      std::this_thread::sleep_for(20ms);
    }
    return true;
  }

  uint16_t port() const { return port_; }
  pid_t pid() const { return pid_; }
  std::string log() const {
    std::ifstream in(log_path_);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }

  void signal(int sig) const {
    if (pid_ > 0) ::kill(pid_, sig);
  }

  // Waits for the process to exit; its exit status (or -signal), nullopt on
  // timeout.
  std::optional<int> wait_exit(std::chrono::milliseconds timeout) {
    const auto deadline = Clock::now() + timeout;
    while (pid_ > 0) {
      int status = 0;
      const pid_t r = ::waitpid(pid_, &status, WNOHANG);
      if (r == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
      }
      if (Clock::now() >= deadline) return std::nullopt;
      std::this_thread::sleep_for(10ms);
    }
    return std::nullopt;
  }

  // A field of /proc/<pid>/status in KiB (VmRSS, RssAnon, VmHWM); -1 if absent.
  long status_kib(const std::string& field) const {
    std::ifstream in("/proc/" + std::to_string(pid_) + "/status");
    std::string line;
    while (std::getline(in, line)) {
      if (line.rfind(field + ":", 0) == 0) return std::stol(line.substr(field.size() + 1));
    }
    return -1;
  }

  void kill_now() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      int status;
      ::waitpid(pid_, &status, 0);
      pid_ = -1;
    }
    if (stdout_fd_ >= 0) ::close(stdout_fd_);
    stdout_fd_ = -1;
  }

 private:
  pid_t pid_ = -1;
  int stdout_fd_ = -1;
  uint16_t port_ = 0;
  std::string log_path_;
};

// How a read ended when it did not produce a message.
enum class ReadEnd { kMessage, kTimeout, kClosed, kBadFrame };

// A blocking client on one TCP connection.
class TestClient {
 public:
  explicit TestClient(size_t max_frame = proto::kMaxServerFrameBytes) : reader_(max_frame) {}
  TestClient(const TestClient&) = delete;
  TestClient& operator=(const TestClient&) = delete;
  TestClient(TestClient&& o) noexcept : fd_(o.fd_), reader_(std::move(o.reader_)) { o.fd_ = -1; }
  ~TestClient() { close(); }

  bool connect(uint16_t port, int receive_buffer = 0) {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd_ < 0) return false;
    if (receive_buffer > 0) {
      ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
    }
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(port);
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    return ::connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
  }
  void close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  int fd() const { return fd_; }

  bool send_raw(const std::vector<uint8_t>& bytes) {
    size_t sent = 0;
    while (sent < bytes.size()) {
      const ssize_t n = ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) return false;
      sent += size_t(n);
    }
    return true;
  }
  bool send(const v1::ClientMessage& m) { return send_raw(proto::encode_frame(m)); }

  bool hello(uint32_t version = proto::kProtocolVersion) {
    v1::ClientMessage m;
    m.mutable_hello()->set_protocol_version(version);
    m.mutable_hello()->set_client_name("net_test");
    return send(m);
  }
  bool list() {
    v1::ClientMessage m;
    m.mutable_list_models();
    return send(m);
  }
  bool cancel() {
    v1::ClientMessage m;
    m.mutable_cancel();
    return send(m);
  }
  bool stream(const v1::StreamRequest& request) {
    v1::ClientMessage m;
    *m.mutable_stream() = request;
    return send(m);
  }
  bool stream(const std::string& model) {
    v1::StreamRequest r;
    r.set_model(model);
    return stream(r);
  }

  // The next server message within `timeout`.
  ReadEnd read(v1::ServerMessage& out, std::chrono::milliseconds timeout = 5000ms) {
    const auto deadline = Clock::now() + timeout;
    while (true) {
      auto m = reader_.next();
      if (!m) return ReadEnd::kBadFrame;
      if (*m) {
        out = std::move(**m);
        return ReadEnd::kMessage;
      }
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
      if (left.count() <= 0) return ReadEnd::kTimeout;
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, int(left.count())) <= 0) return ReadEnd::kTimeout;
      uint8_t buffer[65536];
      const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
      if (n <= 0) return ReadEnd::kClosed;
      reader_.feed(std::span<const uint8_t>(buffer, size_t(n)));
    }
  }

  // Reads until the server closes (true) or `timeout` (false); messages
  // read on the way are appended to `seen`.
  bool wait_closed(std::chrono::milliseconds timeout,
                   std::vector<v1::ServerMessage>* seen = nullptr) {
    const auto deadline = Clock::now() + timeout;
    while (Clock::now() < deadline) {
      v1::ServerMessage m;
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
      const ReadEnd end = read(m, std::max(left, 1ms));
      if (end == ReadEnd::kClosed) return true;
      if (end == ReadEnd::kMessage && seen) seen->push_back(std::move(m));
      if (end == ReadEnd::kBadFrame) return false;
    }
    return false;
  }

 private:
  int fd_ = -1;
  proto::ServerFrameReader reader_;
};

// Everything one stream request produced.
struct StreamResult {
  bool ok = false;  // header ... end seen, chunks contiguous (unless ranged)
  std::string problem;
  v1::StreamHeader header;
  std::vector<v1::Chunk> chunks;
  std::vector<uint8_t> bytes;  // concatenated chunk data
  v1::StreamEnd end;
  std::optional<v1::Error> error;
};

// Reads a stream's replies until StreamEnd or Error. The chunks of a prefix
// must be contiguous from the header's start_offset; a ranged reply
// (StreamHeader.ranged) jumps from range to range, so its caller checks
// the chunks against the ranges it asked for.
inline StreamResult read_stream(TestClient& client, std::chrono::milliseconds timeout = 20000ms) {
  StreamResult r;
  const auto deadline = Clock::now() + timeout;
  bool have_header = false;
  uint64_t next = 0;
  while (true) {
    v1::ServerMessage m;
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0 || client.read(m, left) != ReadEnd::kMessage) {
      r.problem = "stream did not finish";
      return r;
    }
    if (m.has_error()) {
      r.error = m.error();
      r.problem = "error: " + m.error().message();
      return r;
    }
    if (m.has_header()) {
      r.header = m.header();
      have_header = true;
      next = r.header.start_offset();
    } else if (m.has_chunk()) {
      if (!have_header) {
        r.problem = "chunk before header";
        return r;
      }
      if (!r.header.ranged() && m.chunk().offset() != next) {
        r.problem =
            "chunk at " + std::to_string(m.chunk().offset()) + ", expected " + std::to_string(next);
        return r;
      }
      next += m.chunk().data().size();
      r.bytes.insert(r.bytes.end(), m.chunk().data().begin(), m.chunk().data().end());
      r.chunks.push_back(m.chunk());
    } else if (m.has_end()) {
      r.end = m.end();
      r.ok = have_header;
      if (!have_header) r.problem = "end before header";
      return r;
    }
  }
}

}  // namespace meshstream::nettest
