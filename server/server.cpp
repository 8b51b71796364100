#include "server/server.h"

#include <spdlog/spdlog.h>

#include <thread>

#include "proto/framing.h"

namespace meshstream::server {
namespace {

namespace asio = net::asio;
using asio::awaitable;
using asio::use_awaitable;

std::shared_ptr<const std::vector<uint8_t>> hello_frame(const ServerOptions& options) {
  v1::ServerMessage out;
  v1::ServerHello* hello = out.mutable_hello();
  hello->set_protocol_version(proto::kProtocolVersion);
  hello->set_server_name("meshstream-server 0.1.0");
  hello->set_max_client_frame_bytes(options.max_frame_bytes);
  hello->set_max_server_frame_bytes(proto::kMaxServerFrameBytes);
  return std::make_shared<const std::vector<uint8_t>>(proto::encode_frame(out));
}

// Rejecting costs a session too; beyond this many at once we just close.
constexpr int64_t kMaxRejecting = 256;

}  // namespace

Server::Server(const ServerOptions& options)
    : options_(options), first_chunks_(options.first_chunk_hold) {
  shared_.options = &options_;
  shared_.hello_frame = hello_frame(options_);
  shared_.active_sessions = &active_sessions_;
  shared_.rejecting_sessions = &rejecting_;
  shared_.first_chunks = &first_chunks_;
  shared_.metrics = &metrics_;
  unsigned threads = options_.threads ? options_.threads : std::thread::hardware_concurrency();
  threads = std::max(1u, threads);
  for (unsigned i = 0; i < threads; ++i) {
    workers_.push_back(std::make_unique<Worker>());
    Worker* w = workers_.back().get();
    first_chunks_.add_waker([w] { asio::post(w->io, [w] { w->registry.release_held(); }); });
  }
}

Server::~Server() {
  // Before the counters and the catalog it reads go.
  if (metrics_endpoint_) metrics_endpoint_->stop();
}

std::optional<net::tcp::endpoint> Server::metrics_endpoint() const {
  if (!metrics_endpoint_) return std::nullopt;
  return metrics_endpoint_->local_endpoint();
}

Status Server::listen_metrics() {
  metrics_endpoint_ = std::make_unique<MetricsEndpoint>(
      [this] {
        ModelCounts models;
        if (const ModelRegistry* registry = serving_models_.load()) {
          const StateCounts counts = registry->counts();
          models.queued = counts.queued;
          models.encoding = counts.encoding;
          models.ready = counts.ready;
          models.failed = counts.failed;
        }
        return render_prometheus(metrics_, active_sessions_.load(), models);
      },
      [this] {
        if (stopping_) return MetricsEndpoint::Health{false, "shutting down"};
        if (!serving_models_.load() || !initial_models_done_) {
          return MetricsEndpoint::Health{false, "loading models"};
        }
        return MetricsEndpoint::Health{true, ""};
      });
  if (auto status = metrics_endpoint_->listen(options_.metrics_host, options_.metrics_port);
      !status) {
    metrics_endpoint_.reset();
    return status;
  }
  metrics_endpoint_->start();
  return {};
}

Status Server::listen() {
  boost::system::error_code ec;
  auto address = asio::ip::make_address(options_.listen_host, ec);
  if (ec) {
    // A host name (`localhost`, this machine's name): its first address,
    // as a user who writes --listen localhost:7878 expects.
    net::tcp::resolver resolver(workers_[0]->io);
    const auto found = resolver.resolve(options_.listen_host, "", ec);
    if (ec || found.empty()) {
      return make_error(ErrorCode::kIo, "--listen: cannot resolve '" + options_.listen_host +
                                            "': " + (ec ? ec.message() : "no address"));
    }
    // IPv4 first when the name has both (localhost: 127.0.0.1 and ::1), so
    // the clients that write 127.0.0.1 reach it.
    address = found.begin()->endpoint().address();
    for (const auto& entry : found) {
      if (entry.endpoint().address().is_v4()) {
        address = entry.endpoint().address();
        break;
      }
    }
  }
  const net::tcp::endpoint endpoint(address, options_.listen_port);
  auto acceptor = std::make_unique<net::tcp::acceptor>(workers_[0]->io);
  acceptor->open(endpoint.protocol(), ec);
  if (!ec) acceptor->set_option(net::tcp::acceptor::reuse_address(true), ec);
  if (!ec) acceptor->bind(endpoint, ec);
  if (!ec) acceptor->listen(asio::socket_base::max_listen_connections, ec);
  if (ec) {
    return make_error(ErrorCode::kIo, "cannot listen on " + options_.listen_host + ":" +
                                          std::to_string(options_.listen_port) + ": " +
                                          ec.message());
  }
  acceptor_ = std::move(acceptor);
  if (!options_.metrics_host.empty()) return listen_metrics();
  return {};
}

void Server::start_serving(const ModelRegistry& models) {
  shared_.models = &models;
  serving_models_ = &models;
  // Catch SIGINT/SIGTERM from now on (before the port is announced): Asio
  // queues a signal that arrives before run() and delivers it then.
  signals_ = std::make_unique<asio::signal_set>(workers_[0]->io, SIGINT, SIGTERM);
  signals_->async_wait([this](const boost::system::error_code& ec, int signal) {
    if (ec) return;
    spdlog::info("received signal {}", signal);
    stop();
  });
}

net::tcp::endpoint Server::local_endpoint() const {
  boost::system::error_code ec;
  return acceptor_ ? acceptor_->local_endpoint(ec) : net::tcp::endpoint();
}

awaitable<void> Server::accept_loop() {
  asio::steady_timer backoff(workers_[0]->io);
  while (!stopping_) {
    Worker& worker = *workers_[next_worker_];
    next_worker_ = (next_worker_ + 1) % workers_.size();
    boost::system::error_code ec;
    net::tcp::socket socket =
        co_await acceptor_->async_accept(worker.io, asio::redirect_error(use_awaitable, ec));
    if (stopping_) break;
    if (ec) {
      // Out of descriptors or a connection reset before accept: keep serving.
      spdlog::warn("accept failed: {}", ec.message());
      backoff.expires_after(std::chrono::milliseconds(20));
      co_await backoff.async_wait(asio::redirect_error(use_awaitable, ec));
      continue;
    }
    bool reject = false;
    if (active_sessions_.fetch_add(1) >= int64_t(options_.max_connections)) {
      --active_sessions_;
      reject = true;
      if (rejecting_ >= kMaxRejecting) continue;  // socket closes here
      ++rejecting_;
    }
    // The session runs on its worker's thread; hand it over there.
    asio::post(worker.io, [this, &worker, reject, socket = std::move(socket)]() mutable {
      if (stopping_) {  // the socket closes
        if (reject)
          --rejecting_;
        else
          --active_sessions_;
        return;
      }
      auto session =
          std::make_shared<Session>(std::move(socket), shared_, worker.registry, reject, !reject);
      session->start();
    });
  }
}

void Server::stop() {
  if (stopping_.exchange(true)) return;
  asio::post(workers_[0]->io, [this] { begin_shutdown(); });
}

void Server::begin_shutdown() {
  spdlog::info("shutting down: no new connections, closing {} sessions", active_sessions_.load());
  boost::system::error_code ec;
  if (acceptor_) acceptor_->close(ec);
  if (signals_) signals_->cancel(ec);
  for (auto& worker : workers_) {
    asio::post(worker->io, [w = worker.get()] {
      // Copy: shutdown may end sessions, which erase themselves.
      std::vector<Session*> sessions(w->registry.sessions.begin(), w->registry.sessions.end());
      for (Session* s : sessions) {
        if (w->registry.sessions.count(s)) s->shutdown();
      }
      w->guard.reset();  // the io_context returns once its sessions are gone
    });
  }
  std::lock_guard lock(mutex_);
  stopped_.notify_all();
}

void Server::run(std::chrono::milliseconds grace) {
  for (auto& worker : workers_) {
    worker->guard = std::make_unique<asio::executor_work_guard<asio::io_context::executor_type>>(
        worker->io.get_executor());
  }
  asio::co_spawn(workers_[0]->io, accept_loop(), [](std::exception_ptr e) {
    if (!e) return;
    try {
      std::rethrow_exception(e);
    } catch (const std::exception& x) {
      spdlog::error("accept loop failed: {}", x.what());
    }
  });

  std::atomic<size_t> running{workers_.size()};
  std::vector<std::thread> threads;
  for (auto& worker : workers_) {
    threads.emplace_back([this, w = worker.get(), &running] {
      w->io.run();
      --running;
      std::lock_guard lock(mutex_);
      stopped_.notify_all();
    });
  }
  {
    std::unique_lock lock(mutex_);
    stopped_.wait(lock, [&] { return stopping_.load() || running == 0; });
    // Sessions get `grace` to send their last frame and close.
    stopped_.wait_for(lock, grace, [&] { return running == 0; });
  }
  if (running != 0) {
    spdlog::warn("sessions still open after {} ms; stopping anyway", grace.count());
    for (auto& worker : workers_) worker->io.stop();
  }
  for (auto& t : threads) t.join();
  first_chunks_.stop_waking();
  // HAProxy's check sees 503 from stop() on; the endpoint closes with us.
  if (metrics_endpoint_) metrics_endpoint_->stop();
  spdlog::info("server stopped");
}

}  // namespace meshstream::server
