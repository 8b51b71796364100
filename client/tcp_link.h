// One TCP connection as blocking calls with deadlines: connect, write all,
// read some. Each runs a private Asio io_context on the caller's thread and
// can be cancelled through an atomic flag (checked every 20 ms), so a
// client's conversation reads top to bottom. Bytes only: Connection
// (client/connection.h) speaks framed protobuf over it, the HTTP stream path
// (client/http_stream_client.h) HTTP/1.1; each words its own errors.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "common/base/result.h"
#include "common/net/asio.h"

namespace meshstream::client {

class TcpLink {
 public:
  using Millis = std::chrono::milliseconds;

  // Resolves `host` and connects to `port`; kIo "cannot resolve PEER: why"
  // or "cannot connect to PEER: why" (timed out after `timeout`, or
  // cancelled) otherwise. `peer` names the far end in those messages.
  static Result<std::unique_ptr<TcpLink>> open(const std::string& host, uint16_t port,
                                               const std::string& peer, Millis timeout,
                                               const std::atomic<bool>* cancel);
  ~TcpLink();
  TcpLink(const TcpLink&) = delete;
  TcpLink& operator=(const TcpLink&) = delete;

  // Writes every byte, or gives the error (asio::error::timed_out after
  // `timeout`).
  boost::system::error_code write_all(std::span<const uint8_t> bytes, Millis timeout);

  // Up to into.size() bytes. `error` is set when the read ended without
  // bytes or with an error after some: asio::error::eof when the peer
  // closed, timed_out when nothing came for `timeout`, operation_aborted
  // when `cancel` became true.
  struct ReadResult {
    size_t bytes = 0;
    boost::system::error_code error;
  };
  ReadResult read_some(std::span<uint8_t> into, Millis timeout, const std::atomic<bool>* cancel);

  const std::string& peer() const { return peer_; }

 private:
  TcpLink();
  // Runs the io_context until `done`, the deadline or a cancel; cancels the
  // pending operation on timeout. True when the operation completed.
  bool run_until(const bool& done, std::chrono::steady_clock::time_point deadline,
                 const std::atomic<bool>* cancel);

  net::asio::io_context io_;
  net::tcp::socket socket_;
  std::string peer_;
};

// End of file, or a reset or broken pipe because the peer closed with our
// bytes unread.
bool closed_by_peer(const boost::system::error_code& error);

}  // namespace meshstream::client
