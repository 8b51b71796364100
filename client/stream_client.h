// The network side of a streaming session: connect, Hello, StreamRequest
// (with the budget, or a resume offset after a lost connection), then the
// chunks into the DecodedStream. Losing the connection mid-stream reconnects
// with bounded exponential back-off and resumes from the last complete
// record (decoder resume offset), so the final mesh is the same as an
// uninterrupted run's. Also: Hello + ListModels for --list.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "client/connection.h"
#include "client/decoded_stream.h"
#include "client/stream_facts.h"
#include "common/codec/budget.h"

namespace meshstream::client {

// Where the stream stops: the shared meshstream::Budget
// (common/codec/budget.h), sent as the wire's Budget (proto/meshstream.proto).
// kPercentVertices is HCS's "percentage of points" (wire percent_vertices,
// the rule of `meshstream decode --percent`); kPercentBytes is a percent of
// the stream's bytes (wire percent).

struct ReconnectPolicy {
  Millis first_delay{50};
  Millis max_delay{2000};
  int max_attempts = 8;  // consecutive failures without progress
  Millis connect_timeout{5000};
  Millis read_timeout{15000};  // silence that counts as a lost connection
};

struct StreamTarget {
  std::string host;
  uint16_t port = 0;
  std::string model;
  Budget budget;
  uint32_t max_chunk_bytes = 0;  // 0 = server default
  ReconnectPolicy reconnect;
};

// Bytes per second over the last second of reads.
class RateMeter {
 public:
  void add(uint64_t bytes);
  double bytes_per_s() const;

 private:
  mutable std::mutex mutex_;
  std::deque<std::pair<std::chrono::steady_clock::time_point, uint64_t>> samples_;
};

class StreamClient {
 public:
  explicit StreamClient(StreamTarget target) : target_(std::move(target)) {}

  // Streams into `decoded` until the end, the budget, a fatal error or
  // stop(); always calls decoded.finish() before returning. `on_header` runs
  // once, on this thread, when the first header arrives. Blocking: run it on
  // its own thread.
  void run(DecodedStream& decoded, const std::function<void(const StreamFacts&)>& on_header);

  void stop();
  void pause();
  void resume();
  bool paused() const { return paused_.load(); }
  double rate_bytes_per_s() const { return rate_.bytes_per_s(); }
  int reconnects() const { return reconnects_.load(); }
  // Called on the network thread before each back-off (for logs).
  void on_retry(std::function<void(const Error&, int attempt)> f) { on_retry_ = std::move(f); }

 private:
  enum class Attempt { kDone, kRetry, kFatal };
  Attempt attempt(DecodedStream& decoded, const std::function<void(const StreamFacts&)>& on_header,
                  bool& progressed, Error& error);
  bool wait_while_paused();

  StreamTarget target_;
  std::optional<StreamFacts> facts_;
  bool index_checked_ = false;  // header compared with the stream's own index
  std::atomic<bool> stop_{false};
  std::atomic<bool> paused_{false};
  std::atomic<int> reconnects_{0};
  std::mutex pause_mutex_;
  std::condition_variable pause_changed_;
  RateMeter rate_;
  std::function<void(const Error&, int)> on_retry_;
};

// Hello + ListModels on one connection: the catalog, or the error.
Result<std::vector<v1::ModelInfo>> list_models(const std::string& host, uint16_t port,
                                               Millis timeout);

// Hello/ServerHello exchange on an open connection.
Status handshake(Connection& connection, Millis timeout);

}  // namespace meshstream::client
