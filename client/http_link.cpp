#include "client/http_link.h"

namespace meshstream::client {

namespace asio = net::asio;
using Clock = std::chrono::steady_clock;

HttpLink::HttpLink() : socket_(io_) {}
HttpLink::~HttpLink() {
  boost::system::error_code ignored;
  socket_.shutdown(net::tcp::socket::shutdown_both, ignored);
  socket_.close(ignored);
}

bool HttpLink::run_until(const bool& done, Clock::time_point deadline,
                         const std::atomic<bool>* cancel) {
  io_.restart();
  while (!done) {
    const auto now = Clock::now();
    if (now >= deadline || (cancel && cancel->load())) {
      boost::system::error_code ignored;
      socket_.cancel(ignored);
      io_.restart();
      while (!done && io_.run_one_for(Millis(200)) > 0) {
      }
      return false;
    }
    io_.run_one_for(std::min<Clock::duration>(deadline - now, Millis(20)));
  }
  return true;
}

Result<std::unique_ptr<HttpLink>> HttpLink::open(const std::string& host, uint16_t port,
                                                 Millis timeout, const std::atomic<bool>* cancel) {
  std::unique_ptr<HttpLink> link(new HttpLink());
  const std::string where =
      (host.find(':') != std::string::npos ? "[" + host + "]" : host) + ":" + std::to_string(port);
  link->peer_ = where;
  boost::system::error_code ec;
  net::tcp::resolver resolver(link->io_);
  auto endpoints = resolver.resolve(host, std::to_string(port), ec);
  if (ec) return make_error(ErrorCode::kIo, "cannot resolve " + where + ": " + ec.message());
  bool done = false;
  boost::system::error_code result = asio::error::timed_out;
  asio::async_connect(link->socket_, endpoints,
                      [&](const boost::system::error_code& e, const net::tcp::endpoint&) {
                        result = e;
                        done = true;
                      });
  if (!link->run_until(done, Clock::now() + timeout, cancel)) {
    result = cancel && cancel->load() ? asio::error::operation_aborted : asio::error::timed_out;
  }
  if (result)
    return make_error(ErrorCode::kIo, "cannot connect to " + where + ": " + result.message());
  link->socket_.set_option(net::tcp::no_delay(true), ec);
  return link;
}

Status HttpLink::write(const std::string& bytes, Millis timeout) {
  bool done = false;
  boost::system::error_code result = asio::error::timed_out;
  asio::async_write(socket_, asio::buffer(bytes), [&](const boost::system::error_code& e, size_t) {
    result = e;
    done = true;
  });
  if (!run_until(done, Clock::now() + timeout, nullptr)) result = asio::error::timed_out;
  if (result)
    return make_error(ErrorCode::kIo, "sending to " + peer_ + " failed: " + result.message());
  return {};
}

Result<size_t> HttpLink::read_some(std::span<uint8_t> into, Millis timeout,
                                   const std::atomic<bool>* cancel) {
  bool done = false;
  size_t got = 0;
  boost::system::error_code result = asio::error::timed_out;
  socket_.async_read_some(asio::buffer(into.data(), into.size()),
                          [&](const boost::system::error_code& e, size_t n) {
                            result = e;
                            got = n;
                            done = true;
                          });
  if (!run_until(done, Clock::now() + timeout, cancel)) {
    result = (cancel && cancel->load()) ? asio::error::operation_aborted : asio::error::timed_out;
  }
  if (got > 0) return got;
  if (result == asio::error::eof) return size_t{0};
  if (result == asio::error::timed_out) {
    return make_error(ErrorCode::kIo, "server " + peer_ + " sent nothing for " +
                                          std::to_string(timeout.count()) + " ms");
  }
  if (result)
    return make_error(ErrorCode::kIo,
                      "server " + peer_ + " broke the connection: " + result.message());
  return got;
}

}  // namespace meshstream::client
