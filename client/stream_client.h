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

// How one connection attempt of a transport (StreamClient, HttpStreamClient)
// ended: the stream is finished, worth another attempt, or beyond retrying.
enum class AttemptEnd { kDone, kRetry, kFatal };

// The reconnect loop every transport shares: calls `attempt` until it is done
// or fatal, `stop` is set (Ctrl-C: the attempt's error is not reported), or
// `policy.max_attempts` attempts in a row made no progress. Between attempts
// it counts a reconnect, tells `on_retry` (if set) and backs off
// exponentially, bounded by the policy and interrupted by `wake` (under
// `mutex`) once `stop` is set. Finishes `decoded` unless the attempt did
// (kDone).
void run_attempts(DecodedStream& decoded, const ReconnectPolicy& policy,
                  const std::atomic<bool>& stop, std::mutex& mutex, std::condition_variable& wake,
                  std::atomic<int>& reconnects,
                  const std::function<void(const Error&, int attempt)>& on_retry,
                  const std::function<AttemptEnd(bool& progressed, Error& error)>& attempt);

struct StreamTarget {
  std::string host;
  uint16_t port = 0;
  std::string model;
  Budget budget;
  uint32_t max_chunk_bytes = 0;  // 0 = server default
  ReconnectPolicy reconnect;
  // --wait: a model the server is still encoding (Error NOT_READY) is asked
  // for again every `wait_poll` on the same connection until it is ready
  // (then streamed), failed (MODEL_FAILED) or withdrawn (UNKNOWN_MODEL).
  // Without it NOT_READY ends the run.
  bool wait = false;
  Millis wait_poll{500};
};

// "ready", "encoding", "queued" or "failed" (ModelInfo.state; a server that
// predates the field sends none, which means ready).
const char* model_state_name(v1::ModelInfo::State state);

// The stream's true rate: bytes over the time since the first byte arrived,
// and once that is longer than `window`, over the last `window` only (a
// moving average: smooth, and it follows a link that slows down or a
// pause). The first read only starts the clock: its bytes arrived before
// any time could be measured.
class RateMeter {
 public:
  using Clock = std::chrono::steady_clock;
  explicit RateMeter(Clock::duration window = std::chrono::seconds(3)) : window_(window) {}
  void add(uint64_t bytes, Clock::time_point now = Clock::now());
  double bytes_per_s(Clock::time_point now = Clock::now()) const;

 private:
  Clock::duration window_;
  mutable std::mutex mutex_;
  std::optional<Clock::time_point> first_;
  std::deque<std::pair<Clock::time_point, uint64_t>> samples_;  // reads after the first
};

class StreamClient {
 public:
  explicit StreamClient(StreamTarget target) : target_(std::move(target)) {}

  // Streams into `decoded` until the end, the budget, a fatal error or
  // stop(); always calls decoded.finish() before returning. `on_header` runs
  // once, on this thread, when the first header arrives. Blocking: run it on
  // its own thread.
  //
  // Only a connection lost after a successful handshake is retried (and a
  // server that answers BUSY, SHUTTING_DOWN, TIMEOUT or INTERNAL): when the
  // first connection cannot be made (the name does not resolve, nobody
  // listens, the connect times out) or the peer does not answer Hello as a
  // meshstream server, the run fails at once with that reason.
  void run(DecodedStream& decoded, const std::function<void(const StreamFacts&)>& on_header);

  // Checks the first header before anything else is streamed (e.g. that a
  // requested record exists); an error ends the run with it. Set before run.
  void check_header(std::function<Status(const StreamFacts&)> check) {
    check_header_ = std::move(check);
  }

  void stop();
  void pause();
  void resume();
  bool paused() const { return paused_.load(); }
  double rate_bytes_per_s() const { return rate_.bytes_per_s(); }
  int reconnects() const { return reconnects_.load(); }
  // Called on the network thread before each back-off (for logs).
  void on_retry(std::function<void(const Error&, int attempt)> f) { on_retry_ = std::move(f); }
  // Called on the network thread at each NOT_READY while --wait waits, with
  // the model's entry as the server gave it (state, percent, stage).
  void on_waiting(std::function<void(const v1::ModelInfo&)> f) { on_waiting_ = std::move(f); }

 private:
  using Attempt = AttemptEnd;
  Attempt attempt(DecodedStream& decoded, const std::function<void(const StreamFacts&)>& on_header,
                  bool& progressed, Error& error);
  bool wait_while_paused();

  StreamTarget target_;
  std::function<Status(const StreamFacts&)> check_header_;
  bool handshaken_ = false;  // a handshake succeeded once: later losses are retried
  // Before the first handshake: connections the peer closed without a byte.
  static constexpr int kSilentFirstCloseRetries = 3;
  int silent_first_closes_ = 0;
  std::optional<StreamFacts> facts_;
  bool index_checked_ = false;  // header compared with the stream's own index
  std::atomic<bool> stop_{false};
  std::atomic<bool> paused_{false};
  std::atomic<int> reconnects_{0};
  std::mutex pause_mutex_;
  std::condition_variable pause_changed_;
  RateMeter rate_;
  std::function<void(const Error&, int)> on_retry_;
  std::function<void(const v1::ModelInfo&)> on_waiting_;
};

// Hello + ListModels on one connection: the catalog, or the error.
Result<std::vector<v1::ModelInfo>> list_models(const std::string& host, uint16_t port,
                                               Millis timeout);

// Hello/ServerHello exchange on an open connection. `server_answered`, if
// given, tells whether the peer answered as a meshstream server does (a
// ServerHello or a protocol Error) even when the result is an error.
Status handshake(Connection& connection, Millis timeout, bool* server_answered = nullptr);

}  // namespace meshstream::client
