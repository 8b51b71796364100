// One TCP connection to a meshstream server, speaking framed protobuf
// messages (proto/meshstream.proto, proto/framing.h). Blocking calls with
// deadlines on the caller's thread (client/tcp_link.h), so the streaming
// loop reads like the conversation it implements.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "client/tcp_link.h"
#include "common/base/result.h"
#include "proto/framing.h"

namespace meshstream::client {

namespace v1 = ::meshstream::v1;
using Millis = std::chrono::milliseconds;

class Connection {
 public:
  // Resolves `host` and connects to `port`; kIo with the address and the
  // reason when it cannot within `timeout` (or `cancel` became true).
  static Result<std::unique_ptr<Connection>> open(const std::string& host, uint16_t port,
                                                  Millis timeout,
                                                  const std::atomic<bool>* cancel = nullptr);

  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  // Writes one framed message; kIo on a broken connection or timeout.
  Status send(const v1::ClientMessage& message, Millis timeout);

  // The next server message. kIo when the connection closed or broke, or
  // nothing arrived for `timeout`, or `cancel` became true (checked every
  // 20 ms); kLimit / kParse for a frame that breaks the protocol.
  Result<v1::ServerMessage> receive(Millis timeout, const std::atomic<bool>* cancel = nullptr);

  // Stream bytes read from the socket so far (frames included).
  uint64_t bytes_read() const { return bytes_read_; }
  // The peer closed the connection (end of file, or a reset or broken pipe
  // because it closed with our bytes unread).
  bool peer_closed() const { return peer_closed_; }
  std::string peer() const { return link_->peer(); }

 private:
  explicit Connection(std::unique_ptr<TcpLink> link);

  std::unique_ptr<TcpLink> link_;
  proto::ServerFrameReader reader_{proto::kMaxServerFrameBytes};
  std::vector<uint8_t> buffer_;
  uint64_t bytes_read_ = 0;
  bool peer_closed_ = false;
};

// Splits "HOST:PORT" ("[::1]:7878" for IPv6). kInvalidArgument otherwise.
struct HostPort {
  std::string host;
  uint16_t port = 0;
};
Result<HostPort> parse_host_port(const std::string& text);

}  // namespace meshstream::client
