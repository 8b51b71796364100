#include "client/tcp_link.h"

namespace meshstream::client {

namespace asio = net::asio;
using Clock = std::chrono::steady_clock;

TcpLink::TcpLink() : socket_(io_) {}

TcpLink::~TcpLink() {
  boost::system::error_code ignored;
  socket_.shutdown(net::tcp::socket::shutdown_both, ignored);
  socket_.close(ignored);
}

bool TcpLink::run_until(const bool& done, Clock::time_point deadline,
                        const std::atomic<bool>* cancel) {
  io_.restart();
  while (!done) {
    const auto now = Clock::now();
    if (now >= deadline || (cancel && cancel->load())) {
      boost::system::error_code ignored;
      socket_.cancel(ignored);
      // Let the cancelled handler run so no operation outlives this call.
      io_.restart();
      while (!done && io_.run_one_for(Millis(200)) > 0) {
      }
      return false;
    }
    io_.run_one_for(std::min<Clock::duration>(deadline - now, Millis(20)));
  }
  return true;
}

Result<std::unique_ptr<TcpLink>> TcpLink::open(const std::string& host, uint16_t port,
                                               const std::string& peer, Millis timeout,
                                               const std::atomic<bool>* cancel) {
  std::unique_ptr<TcpLink> link(new TcpLink());
  link->peer_ = peer;
  boost::system::error_code ec;
  net::tcp::resolver resolver(link->io_);
  auto endpoints = resolver.resolve(host, std::to_string(port), ec);
  if (ec) return make_error(ErrorCode::kIo, "cannot resolve " + peer + ": " + ec.message());
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
    return make_error(ErrorCode::kIo, "cannot connect to " + peer + ": " + result.message());
  link->socket_.set_option(net::tcp::no_delay(true), ec);
  return link;
}

boost::system::error_code TcpLink::write_all(std::span<const uint8_t> bytes, Millis timeout) {
  bool done = false;
  boost::system::error_code result = asio::error::timed_out;
  asio::async_write(socket_, asio::buffer(bytes.data(), bytes.size()),
                    [&](const boost::system::error_code& e, size_t) {
                      result = e;
                      done = true;
                    });
  if (!run_until(done, Clock::now() + timeout, nullptr)) result = asio::error::timed_out;
  return result;
}

TcpLink::ReadResult TcpLink::read_some(std::span<uint8_t> into, Millis timeout,
                                       const std::atomic<bool>* cancel) {
  bool done = false;
  ReadResult read;
  read.error = asio::error::timed_out;
  socket_.async_read_some(asio::buffer(into.data(), into.size()),
                          [&](const boost::system::error_code& e, size_t n) {
                            read.error = e;
                            read.bytes = n;
                            done = true;
                          });
  if (!run_until(done, Clock::now() + timeout, cancel)) {
    read.error =
        (cancel && cancel->load()) ? asio::error::operation_aborted : asio::error::timed_out;
  }
  return read;
}

bool closed_by_peer(const boost::system::error_code& error) {
  return error == net::asio::error::eof || error == net::asio::error::connection_reset ||
         error == net::asio::error::broken_pipe;
}

}  // namespace meshstream::client
