// The meshstream server: one io_context per worker thread (a thread per
// core), an acceptor that deals new connections round-robin to the workers,
// --max-connections, and a clean stop on SIGINT/SIGTERM (stop accepting,
// send every session Error{SHUTTING_DOWN}, wait for them to close, exit).
#pragma once

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "common/base/result.h"
#include "common/net/asio.h"
#include "server/metrics_http.h"
#include "server/model_registry.h"
#include "server/server_options.h"
#include "server/session.h"

namespace meshstream::server {

class Server {
 public:
  explicit Server(const ServerOptions& options);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds and listens on options.listen_host:listen_port, first of all, so
  // an unusable address fails at once (and starts the --metrics endpoint,
  // whose /healthz says 503 until start_serving). Clients that connect
  // before run() wait in the backlog. kIo when the address is unusable (in
  // use, not local, not an
  // address); the message names it and the cause.
  Status listen();
  // The bound address (after listen()); port is the real one for port 0.
  net::tcp::endpoint local_endpoint() const;
  // The --metrics address (after listen()); nullopt without --metrics.
  std::optional<net::tcp::endpoint> metrics_endpoint() const;

  // What the server serves (must outlive it; it may change while the
  // server runs: models are encoded in the background), and from now on
  // SIGINT/SIGTERM mean stop(). Call after listen(), before announcing the
  // port and run().
  void start_serving(const ModelRegistry& models);

  // Serves until stop() or SIGINT/SIGTERM, then shuts down cleanly (sessions
  // get up to `grace` to close) and returns. Blocks the calling thread.
  void run(std::chrono::milliseconds grace = std::chrono::milliseconds(3000));
  // Thread-safe, idempotent: begins the clean shutdown.
  void stop();
  // Thread-safe: every model found at start is ready or failed; from now on
  // /healthz answers 200 (a load balancer sends clients only then).
  void initial_models_done() { initial_models_done_ = true; }

 private:
  struct Worker {
    SessionRegistry registry;  // destroyed after the io_context and its sessions
    net::asio::io_context io{1};
    std::unique_ptr<net::asio::executor_work_guard<net::asio::io_context::executor_type>> guard;
  };

  net::asio::awaitable<void> accept_loop();
  void begin_shutdown();  // on worker 0
  Status listen_metrics();

  const ServerOptions& options_;
  FirstChunkGate first_chunks_;
  ServerMetrics metrics_;
  std::atomic<const ModelRegistry*> serving_models_{nullptr};  // for /metrics, set by start_serving
  std::unique_ptr<MetricsEndpoint> metrics_endpoint_;
  ServerShared shared_;
  std::atomic<int64_t> active_sessions_{0};
  std::atomic<int64_t> rejecting_{0};
  std::vector<std::unique_ptr<Worker>> workers_;
  std::unique_ptr<net::tcp::acceptor> acceptor_;
  std::unique_ptr<net::asio::signal_set> signals_;
  std::atomic<bool> stopping_{false};
  std::atomic<bool> initial_models_done_{false};
  std::mutex mutex_;
  std::condition_variable stopped_;
  size_t next_worker_ = 0;
};

}  // namespace meshstream::server
