// The `--metrics HOST:PORT` endpoint: a small HTTP/1.1 server (Boost.Beast)
// on its own thread and io_context, so a scrape never waits behind the
// streaming workers and a slow or hostile scraper never slows a stream.
//   GET|HEAD /metrics  200, the Prometheus text format (text/plain; version=0.0.4)
//   GET|HEAD /healthz  200 "ok" while serving, 503 while loading or stopping
//   other paths 404, other methods 405, unparsable requests 400 + close.
// Each connection gets kRequestTimeout to send a request; at most
// kMaxConnections are open at once (more are closed at accept).
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "common/base/result.h"
#include "common/net/asio.h"

namespace meshstream::server {

class MetricsEndpoint {
 public:
  // What /healthz answers: 200 when `serving` is true, else 503 with the
  // reason; /metrics calls `render` for its body (on the endpoint's thread).
  struct Health {
    bool serving = false;
    std::string reason;  // when not serving: "loading", "shutting down"
  };
  MetricsEndpoint(std::function<std::string()> render, std::function<Health()> health);
  ~MetricsEndpoint();  // stops it
  MetricsEndpoint(const MetricsEndpoint&) = delete;
  MetricsEndpoint& operator=(const MetricsEndpoint&) = delete;

  // Binds and listens; kIo naming the address when it is unusable.
  Status listen(const std::string& host, uint16_t port);
  net::tcp::endpoint local_endpoint() const;
  // Starts answering on its own thread. After listen().
  void start();
  // Closes the listener and every connection and joins the thread. Idempotent.
  void stop();

 private:
  net::asio::awaitable<void> accept_loop();
  net::asio::awaitable<void> serve(net::tcp::socket socket);

  std::function<std::string()> render_;
  std::function<Health()> health_;
  net::asio::io_context io_{1};
  std::unique_ptr<net::tcp::acceptor> acceptor_;
  std::thread thread_;
  std::atomic<int> connections_{0};
};

}  // namespace meshstream::server
