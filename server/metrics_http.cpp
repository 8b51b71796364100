#include "server/metrics_http.h"

// clang-format off
#include "common/net/asio.h"  // first: <utility> before Boost (see asio.h)
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
// clang-format on
#include <spdlog/spdlog.h>

namespace meshstream::server {
namespace {

namespace asio = net::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using asio::awaitable;
using asio::use_awaitable;

constexpr auto kRequestTimeout = std::chrono::seconds(10);
constexpr int kMaxConnections = 64;
constexpr size_t kMaxHeaderBytes = 8 * 1024;  // a scrape request is a few hundred bytes

http::response<http::string_body> answer(const http::request<http::empty_body>& request,
                                         const std::function<std::string()>& render,
                                         const MetricsEndpoint::Health& health) {
  http::response<http::string_body> response;
  response.version(11);
  response.keep_alive(request.keep_alive());
  response.set(http::field::server, "meshstream-server");
  response.set(http::field::content_type, "text/plain; charset=utf-8");
  const std::string_view target(request.target().data(), request.target().size());
  const std::string_view path = target.substr(0, target.find('?'));
  if (request.method() != http::verb::get && request.method() != http::verb::head) {
    response.result(http::status::method_not_allowed);
    response.set(http::field::allow, "GET, HEAD");
    response.body() = "only GET and HEAD\n";
  } else if (path == "/metrics") {
    response.result(http::status::ok);
    response.set(http::field::content_type, "text/plain; version=0.0.4; charset=utf-8");
    response.body() = render();
  } else if (path == "/healthz") {
    response.result(health.serving ? http::status::ok : http::status::service_unavailable);
    response.body() = health.serving ? "ok\n" : health.reason + "\n";
  } else {
    response.result(http::status::not_found);
    response.body() = "not found; this endpoint serves /metrics and /healthz\n";
  }
  response.prepare_payload();
  // HEAD: same headers (Content-Length of the GET body), no body.
  if (request.method() == http::verb::head) response.body().clear();
  return response;
}

}  // namespace

MetricsEndpoint::MetricsEndpoint(std::function<std::string()> render,
                                 std::function<Health()> health)
    : render_(std::move(render)), health_(std::move(health)) {}

MetricsEndpoint::~MetricsEndpoint() { stop(); }

Status MetricsEndpoint::listen(const std::string& host, uint16_t port) {
  boost::system::error_code ec;
  auto address = asio::ip::make_address(host, ec);
  if (ec) {
    net::tcp::resolver resolver(io_);
    const auto found = resolver.resolve(host, "", ec);
    if (ec || found.empty()) {
      return make_error(ErrorCode::kIo, "--metrics: cannot resolve '" + host +
                                            "': " + (ec ? ec.message() : "no address"));
    }
    address = found.begin()->endpoint().address();
  }
  auto acceptor = std::make_unique<net::tcp::acceptor>(io_);
  const net::tcp::endpoint endpoint(address, port);
  acceptor->open(endpoint.protocol(), ec);
  if (!ec) acceptor->set_option(net::tcp::acceptor::reuse_address(true), ec);
  if (!ec) acceptor->bind(endpoint, ec);
  if (!ec) acceptor->listen(asio::socket_base::max_listen_connections, ec);
  if (ec) {
    return make_error(ErrorCode::kIo, "--metrics: cannot listen on " + host + ":" +
                                          std::to_string(port) + ": " + ec.message());
  }
  acceptor_ = std::move(acceptor);
  return {};
}

net::tcp::endpoint MetricsEndpoint::local_endpoint() const {
  boost::system::error_code ec;
  return acceptor_ ? acceptor_->local_endpoint(ec) : net::tcp::endpoint();
}

void MetricsEndpoint::start() {
  if (!acceptor_ || thread_.joinable()) return;
  asio::co_spawn(io_, accept_loop(), asio::detached);
  thread_ = std::thread([this] { io_.run(); });
}

void MetricsEndpoint::stop() {
  if (!thread_.joinable()) return;
  // Stopping the io_context abandons the coroutines; their sockets close
  // when the io_context is destroyed with them.
  io_.stop();
  thread_.join();
}

awaitable<void> MetricsEndpoint::accept_loop() {
  asio::steady_timer backoff(io_);
  for (;;) {
    boost::system::error_code ec;
    net::tcp::socket socket =
        co_await acceptor_->async_accept(asio::redirect_error(use_awaitable, ec));
    if (ec == asio::error::operation_aborted) co_return;
    if (ec) {
      spdlog::warn("metrics: accept failed: {}", ec.message());
      backoff.expires_after(std::chrono::milliseconds(20));
      co_await backoff.async_wait(asio::redirect_error(use_awaitable, ec));
      continue;
    }
    if (connections_ >= kMaxConnections) continue;  // the socket closes here
    asio::co_spawn(io_, serve(std::move(socket)), asio::detached);
  }
}

awaitable<void> MetricsEndpoint::serve(net::tcp::socket socket) {
  ++connections_;
  beast::tcp_stream stream(std::move(socket));
  beast::flat_buffer buffer;
  for (;;) {
    stream.expires_after(kRequestTimeout);
    http::request_parser<http::empty_body> parser;
    parser.header_limit(kMaxHeaderBytes);
    parser.body_limit(0);  // a GET has no body; one with a body is refused
    boost::system::error_code ec;
    co_await http::async_read(stream, buffer, parser, asio::redirect_error(use_awaitable, ec));
    if (ec == http::error::end_of_stream || ec == beast::error::timeout ||
        ec == asio::error::connection_reset || ec == asio::error::eof) {
      break;
    }
    if (ec) {
      // Garbage, an oversized header, a body: one 400 and close.
      http::response<http::string_body> bad{http::status::bad_request, 11};
      bad.set(http::field::server, "meshstream-server");
      bad.set(http::field::content_type, "text/plain; charset=utf-8");
      bad.set(http::field::connection, "close");
      bad.body() = "bad request: " + ec.message() + "\n";
      bad.prepare_payload();
      co_await http::async_write(stream, bad, asio::redirect_error(use_awaitable, ec));
      break;
    }
    const http::request<http::empty_body> request = parser.release();
    auto response = answer(request, render_, health_());
    const bool keep_alive = response.keep_alive();
    http::serializer<false, http::string_body> serializer(response);
    if (request.method() == http::verb::head) serializer.split(true);
    if (request.method() == http::verb::head) {
      co_await http::async_write_header(stream, serializer,
                                        asio::redirect_error(use_awaitable, ec));
    } else {
      co_await http::async_write(stream, serializer, asio::redirect_error(use_awaitable, ec));
    }
    if (ec || !keep_alive) break;
  }
  boost::system::error_code ignored;
  stream.socket().shutdown(net::tcp::socket::shutdown_send, ignored);
  --connections_;
}

}  // namespace meshstream::server
