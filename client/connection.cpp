#include "client/connection.h"

#include <charconv>

namespace meshstream::client {

Connection::Connection(std::unique_ptr<TcpLink> link)
    : link_(std::move(link)), buffer_(256 * 1024) {}

Result<std::unique_ptr<Connection>> Connection::open(const std::string& host, uint16_t port,
                                                     Millis timeout,
                                                     const std::atomic<bool>* cancel) {
  auto link = TcpLink::open(host, port, host + ":" + std::to_string(port), timeout, cancel);
  if (!link) return tl::unexpected(link.error());
  return std::unique_ptr<Connection>(new Connection(std::move(*link)));
}

Status Connection::send(const v1::ClientMessage& message, Millis timeout) {
  const std::vector<uint8_t> frame = proto::encode_frame(message);
  const boost::system::error_code result = link_->write_all(frame, timeout);
  peer_closed_ |= closed_by_peer(result);
  if (result)
    return make_error(ErrorCode::kIo, "sending to " + peer() + " failed: " + result.message());
  return {};
}

Result<v1::ServerMessage> Connection::receive(Millis timeout, const std::atomic<bool>* cancel) {
  while (true) {
    auto next = reader_.next();
    if (!next) {
      return make_error(next.error().code,
                        "server " + peer() + " sent a bad frame: " + next.error().message);
    }
    if (*next) return std::move(**next);
    const auto [got, result] = link_->read_some(buffer_, timeout, cancel);
    if (got > 0) {
      bytes_read_ += got;
      reader_.feed(std::span<const uint8_t>(buffer_.data(), got));
    }
    if (result) {
      if (got > 0) continue;  // parse what arrived first
      peer_closed_ |= closed_by_peer(result);
      const std::string why = result == net::asio::error::eof ? "closed the connection"
                              : result == net::asio::error::timed_out
                                  ? "sent nothing for " + std::to_string(timeout.count()) + " ms"
                                  : "broke the connection: " + result.message();
      return make_error(ErrorCode::kIo, "server " + peer() + " " + why);
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
