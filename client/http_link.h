// One TCP connection to a web server for the HTTP stream path: blocking
// connect, write and read calls with deadlines on the caller's thread (a
// private Asio io_context), cancellable through an atomic flag, as
// client/connection.h does for the meshstream protocol. Bytes only: the
// HTTP itself is client/http_response.h.
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

class HttpLink {
 public:
  using Millis = std::chrono::milliseconds;
  // kIo naming HOST:PORT and the reason when it cannot connect within
  // `timeout` (or `cancel` became true).
  static Result<std::unique_ptr<HttpLink>> open(const std::string& host, uint16_t port,
                                                Millis timeout, const std::atomic<bool>* cancel);
  ~HttpLink();
  HttpLink(const HttpLink&) = delete;
  HttpLink& operator=(const HttpLink&) = delete;

  Status write(const std::string& bytes, Millis timeout);
  // Up to into.size() bytes; 0 when the server closed the connection. kIo
  // when nothing arrived for `timeout`, the connection broke, or `cancel`.
  Result<size_t> read_some(std::span<uint8_t> into, Millis timeout,
                           const std::atomic<bool>* cancel);
  const std::string& peer() const { return peer_; }

 private:
  HttpLink();
  bool run_until(const bool& done, std::chrono::steady_clock::time_point deadline,
                 const std::atomic<bool>* cancel);

  net::asio::io_context io_;
  net::tcp::socket socket_;
  std::string peer_;
};

}  // namespace meshstream::client
