#include "client/connection.h"

#include <charconv>

namespace meshstream::client {

using Clock = std::chrono::steady_clock;

Connection::Connection() : socket_(io_), buffer_(256 * 1024) {}
Connection::~Connection() {
  boost::system::error_code ignored;
  socket_.shutdown(tcp::socket::shutdown_both, ignored);
  socket_.close(ignored);
}

bool Connection::run_until(const bool& done, Clock::time_point deadline,
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

Result<std::unique_ptr<Connection>> Connection::open(const std::string& host, uint16_t port,
                                                     Millis timeout,
                                                     const std::atomic<bool>* cancel) {
  std::unique_ptr<Connection> c(new Connection());
  const std::string where = host + ":" + std::to_string(port);
  c->peer_ = where;
  boost::system::error_code ec;
  tcp::resolver resolver(c->io_);
  auto endpoints = resolver.resolve(host, std::to_string(port), ec);
  if (ec) return make_error(ErrorCode::kIo, "cannot resolve " + where + ": " + ec.message());
  bool done = false;
  boost::system::error_code result = asio::error::timed_out;
  asio::async_connect(c->socket_, endpoints,
                      [&](const boost::system::error_code& e, const tcp::endpoint&) {
                        result = e;
                        done = true;
                      });
  if (!c->run_until(done, Clock::now() + timeout, cancel)) {
    result = cancel && cancel->load() ? asio::error::operation_aborted : asio::error::timed_out;
  }
  if (result)
    return make_error(ErrorCode::kIo, "cannot connect to " + where + ": " + result.message());
  c->socket_.set_option(tcp::no_delay(true), ec);
  return c;
}

namespace {

// End of file, or a reset because the peer closed with our bytes unread.
bool closed_by_peer(const boost::system::error_code& e) {
  return e == asio::error::eof || e == asio::error::connection_reset ||
         e == asio::error::broken_pipe;
}

}  // namespace

Status Connection::send(const v1::ClientMessage& message, Millis timeout) {
  const std::vector<uint8_t> frame = proto::encode_frame(message);
  bool done = false;
  boost::system::error_code result = asio::error::timed_out;
  asio::async_write(socket_, asio::buffer(frame), [&](const boost::system::error_code& e, size_t) {
    result = e;
    done = true;
  });
  if (!run_until(done, Clock::now() + timeout, nullptr)) result = asio::error::timed_out;
  peer_closed_ |= closed_by_peer(result);
  if (result)
    return make_error(ErrorCode::kIo, "sending to " + peer_ + " failed: " + result.message());
  return {};
}

Result<v1::ServerMessage> Connection::receive(Millis timeout, const std::atomic<bool>* cancel) {
  while (true) {
    auto next = reader_.next();
    if (!next) {
      return make_error(next.error().code,
                        "server " + peer_ + " sent a bad frame: " + next.error().message);
    }
    if (*next) return std::move(**next);
    bool done = false;
    size_t got = 0;
    boost::system::error_code result = asio::error::timed_out;
    socket_.async_read_some(asio::buffer(buffer_),
                            [&](const boost::system::error_code& e, size_t n) {
                              result = e;
                              got = n;
                              done = true;
                            });
    if (!run_until(done, Clock::now() + timeout, cancel)) {
      result = (cancel && cancel->load()) ? asio::error::operation_aborted : asio::error::timed_out;
    }
    if (got > 0) {
      bytes_read_ += got;
      reader_.feed(std::span<const uint8_t>(buffer_.data(), got));
    }
    if (result) {
      if (got > 0) continue;  // parse what arrived first
      peer_closed_ |= closed_by_peer(result);
      const std::string why = result == asio::error::eof ? "closed the connection"
                              : result == asio::error::timed_out
                                  ? "sent nothing for " + std::to_string(timeout.count()) + " ms"
                                  : "broke the connection: " + result.message();
      return make_error(ErrorCode::kIo, "server " + peer_ + " " + why);
    }
  }
}

Result<HostPort> parse_host_port(const std::string& text) {
  auto malformed = [&](const std::string& why) {
    return make_error(ErrorCode::kInvalidArgument, "'" + text + "' is not HOST:PORT (" + why + ")");
  };
  const size_t colon = text.rfind(':');
  if (colon == std::string::npos) return malformed("no ':' before a port");
  if (colon == 0) return malformed("no host before the ':'");
  if (colon + 1 == text.size()) return malformed("no port after the ':'");
  HostPort hp;
  hp.host = text.substr(0, colon);
  if (hp.host.size() >= 2 && hp.host.front() == '[' && hp.host.back() == ']') {
    hp.host = hp.host.substr(1, hp.host.size() - 2);
  }
  const std::string port = text.substr(colon + 1);
  const bool negative = port.size() > 1 && port[0] == '-' &&
                        port.find_first_not_of("0123456789", 1) == std::string::npos;
  if (negative) {
    return make_error(ErrorCode::kInvalidArgument,
                      "port " + port + " in '" + text + "' is out of range: a port is 1 to 65535");
  }
  unsigned long long value = 0;
  auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
  if (end != port.data() + port.size() || ec == std::errc::invalid_argument) {
    return malformed("the port '" + port + "' is not a number");
  }
  if (ec == std::errc::result_out_of_range || value == 0 || value > 65535) {
    return make_error(ErrorCode::kInvalidArgument,
                      "port " + port + " in '" + text + "' is out of range: a port is 1 to 65535");
  }
  hp.port = static_cast<uint16_t>(value);
  return hp;
}

}  // namespace meshstream::client
