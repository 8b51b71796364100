// A tiny TCP proxy for fault tests: forwards one client connection at a time
// to a server on loopback and, on the first connection only, flips one byte
// in the middle of the data of the N-th Chunk it relays from the server (the
// frame is re-encoded, so framing stays valid: this is corruption of stream
// bytes that TCP's own checksum missed). Later connections pass untouched,
// so a client that re-requests gets clean bytes.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include "proto/framing.h"

namespace meshstream::faulttest {

class ByteFlipProxy {
 public:
  ByteFlipProxy(uint16_t server_port, int corrupt_chunk)
      : server_port_(server_port), corrupt_chunk_(corrupt_chunk) {
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    int one = 1;
    ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(listen_fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
    ::listen(listen_fd_, 8);
    socklen_t len = sizeof a;
    ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] { run(); });
  }
  ~ByteFlipProxy() {
    stop_ = true;
    thread_.join();
    ::close(listen_fd_);
  }
  uint16_t port() const { return port_; }
  int connections() const { return connections_.load(); }
  bool flipped() const { return flipped_.load(); }

 private:
  static bool send_all(int fd, const uint8_t* p, size_t n) {
    while (n > 0) {
      const ssize_t w = ::send(fd, p, n, MSG_NOSIGNAL);
      if (w <= 0) return false;
      p += w;
      n -= size_t(w);
    }
    return true;
  }

  void run() {
    while (!stop_) {
      pollfd p{listen_fd_, POLLIN, 0};
      if (::poll(&p, 1, 50) <= 0) continue;
      const int client = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
      if (client < 0) continue;
      const int server = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
      sockaddr_in a{};
      a.sin_family = AF_INET;
      a.sin_port = htons(server_port_);
      a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      if (::connect(server, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) {
        relay(client, server, ++connections_ == 1);
      }
      ::close(server);
      ::close(client);
    }
  }

  // Client bytes pass through as they are; server bytes are parsed into
  // frames and re-encoded (byte-identical) so one chunk can be altered.
  void relay(int client, int server, bool corrupt) {
    proto::ServerFrameReader reader(proto::kMaxServerFrameBytes);
    int chunks = 0;
    std::vector<uint8_t> buffer(1 << 16);
    while (!stop_) {
      pollfd p[2] = {{client, POLLIN, 0}, {server, POLLIN, 0}};
      if (::poll(p, 2, 50) <= 0) continue;
      if (p[0].revents) {
        const ssize_t n = ::recv(client, buffer.data(), buffer.size(), 0);
        if (n <= 0 || !send_all(server, buffer.data(), size_t(n))) return;
      }
      if (p[1].revents) {
        const ssize_t n = ::recv(server, buffer.data(), buffer.size(), 0);
        if (n <= 0) return;
        reader.feed(std::span<const uint8_t>(buffer.data(), size_t(n)));
        while (true) {
          auto m = reader.next();
          if (!m || !*m) break;
          v1::ServerMessage message = std::move(**m);
          if (corrupt && message.has_chunk() && !message.chunk().data().empty() &&
              ++chunks == corrupt_chunk_) {
            std::string& data = *message.mutable_chunk()->mutable_data();
            data[data.size() / 2] ^= 0x5a;
            flipped_ = true;
          }
          const std::vector<uint8_t> frame = proto::encode_frame(message);
          if (!send_all(client, frame.data(), frame.size())) return;
        }
      }
    }
  }

  uint16_t server_port_;
  int corrupt_chunk_;
  int listen_fd_ = -1;
  uint16_t port_ = 0;
  std::atomic<bool> stop_{false};
  std::atomic<int> connections_{0};
  std::atomic<bool> flipped_{false};
  std::thread thread_;
};

}  // namespace meshstream::faulttest
