// One client connection: three coroutines on the io_context of one worker
// thread (so no locks): a reader that parses frames and handles requests, a
// writer that owns the socket's only write in flight (control frames first,
// then the running stream's chunks, paced), and a watchdog that enforces the
// handshake, idle, stall and linger deadlines. The session lives as long as
// any of them runs; closing the socket ends all three. Errors of one session
// never leave it. Protocol rules: proto/meshstream.proto.
#pragma once

#include <chrono>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <unordered_set>
#include <variant>
#include <vector>

#include "common/net/asio.h"
#include "proto/framing.h"
#include "server/catalog.h"
#include "server/first_chunk_gate.h"
#include "server/model_registry.h"
#include "server/server_metrics.h"
#include "server/server_options.h"
#include "server/stream_plan.h"
#include "server/token_bucket.h"

namespace meshstream::server {

class Session;

// Shared, immutable for the server's lifetime (read from every thread).
struct ServerShared {
  const ServerOptions* options = nullptr;
  // The models and their states; thread-safe, changes while serving.
  const ModelRegistry* models = nullptr;
  std::shared_ptr<const std::vector<uint8_t>> hello_frame;  // ServerHello, pre-encoded
  std::atomic<int64_t>* active_sessions = nullptr;          // counted toward --max-connections
  std::atomic<int64_t>* rejecting_sessions = nullptr;       // busy sessions still closing
  FirstChunkGate* first_chunks = nullptr;  // bulk waits for new streams' first chunks
  ServerMetrics* metrics = nullptr;        // counters for --metrics (atomics)
};

// The sessions of one worker thread, touched only from that thread.
struct SessionRegistry {
  std::unordered_set<Session*> sessions;
  // Sessions whose bulk chunk waits while FirstChunkGate holds bulk; the
  // gate's waker releases them all when the first chunks are out.
  std::unordered_set<Session*> held;
  void release_held();
};

class Session : public std::enable_shared_from_this<Session> {
 public:
  using Clock = std::chrono::steady_clock;

  // `reject` = the server is full: the session only sends Error{BUSY} and
  // closes. `counted` = it holds one of --max-connections (released when it
  // ends).
  Session(net::tcp::socket socket, const ServerShared& shared, SessionRegistry& registry,
          bool reject, bool counted);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  // Registers and starts the coroutines. Call on the socket's executor.
  void start();
  // Server stopping: send Error{SHUTTING_DOWN} after the chunk in flight,
  // then close. Call on the socket's executor.
  void shutdown();
  // The first-chunk hold is over: a held bulk chunk may go. Call on the
  // socket's executor.
  void release_bulk() { wake(writer_wake_); }

 private:
  struct Frame {
    std::shared_ptr<const std::vector<uint8_t>> bytes;
    bool closing = false;  // close gracefully after writing it
  };
  struct StartStream {
    // Held from the request on: the registry may withdraw or replace the
    // model meanwhile, this stream still finishes with these bytes.
    std::shared_ptr<const CatalogModel> model;
    StreamPlan plan;
    size_t chunk_bytes = 0;
    Clock::time_point requested;  // when its request was read
    bool compact_index = false;   // StreamRequest.compact_index
  };
  struct CancelStream {};
  using Item = std::variant<Frame, StartStream, CancelStream>;

  struct ActiveStream {
    std::shared_ptr<const CatalogModel> model;
    StreamPlan plan;
    std::vector<ByteSegment> segments;  // plan_segments(plan), sent in order
    size_t segment = 0;                 // the one `position` is in
    size_t chunk_bytes = 0;
    Clock::time_point requested;
    TokenBucket bucket;
    uint64_t position = 0;  // next byte to send
    uint32_t records_complete = 0;
    uint64_t bytes_sent = 0;
    uint32_t chunks_sent = 0;
    bool yielded = false;  // this chunk already stepped back once for new streams

    bool all_sent() const {
      return segments.empty() ||
             (segment + 1 == segments.size() && position >= segments.back().end);
    }
  };

  net::asio::awaitable<void> read_loop(std::shared_ptr<Session> self);
  net::asio::awaitable<void> write_loop(std::shared_ptr<Session> self);
  net::asio::awaitable<void> watchdog(std::shared_ptr<Session> self);

  // The writer's phases (write_loop runs the first that applies, then looks
  // again). Each returns false when the writer must stop: the connection
  // closed, or our closing frame went out.
  // A pending stream header that cannot ride with a first chunk.
  bool header_must_go_alone() const;
  net::asio::awaitable<bool> write_header_alone();
  // The oldest queued control item: a frame, a new stream or a cancel.
  net::asio::awaitable<bool> write_queued_item();
  net::asio::awaitable<bool> write_frame(const Frame& frame);
  net::asio::awaitable<bool> begin_stream(const StartStream& start);
  // The running stream: its next chunk, or its StreamEnd once all is sent.
  net::asio::awaitable<bool> write_stream_step();
  net::asio::awaitable<bool> write_chunk(ActiveStream& stream);
  // Nothing to write: sleeps until push() or close wakes the writer.
  net::asio::awaitable<void> wait_for_work();

  // Writes `buffers` as the one write in flight; false (and closed) on failure.
  template <class Buffers>
  net::asio::awaitable<bool> write(const Buffers& buffers);
  net::asio::awaitable<bool> write_end(v1::StreamEnd::Reason reason);

  void handle(const v1::ClientMessage& message);
  void handle_stream(const v1::StreamRequest& request);
  void push(Item item, size_t bytes);
  void send(const google::protobuf::MessageLite& message, bool closing = false);
  void send_error(v1::Error::Code code, const std::string& message, bool closing);
  // NOT_READY (queued, encoding) or MODEL_FAILED for a model with no stream.
  void send_not_servable(const ModelStatus& status);
  // Fatal for the connection: error frame, then graceful close.
  void fail(v1::Error::Code code, const std::string& message, const std::string& log_reason);
  void close_now(const std::string& reason);
  void set_end_reason(const std::string& reason);
  void wake(net::asio::steady_timer& timer) { timer.cancel(); }

  net::tcp::socket socket_;
  const ServerShared& shared_;
  SessionRegistry& registry_;
  const bool reject_;
  const bool counted_;
  std::string peer_;

  proto::ClientFrameReader reader_;
  std::deque<Item> queue_;
  size_t queued_bytes_ = 0;
  std::optional<ActiveStream> stream_;
  // The running stream's header, sent together with its first chunk (one
  // write instead of two: under load each write waits a full round of the
  // worker's queue).
  std::vector<uint8_t> pending_header_;
  int starting_ = 0;  // this session's share of FirstChunkGate::starting()
  void started_one() {
    if (starting_ > 0) {
      --starting_;
      shared_.first_chunks->stream_started();
    }
  }
  // Before a bulk chunk: waits while the gate holds bulk for new streams'
  // first chunks, or until this session has a control item queued (those are
  // never held). False if the session closed meanwhile.
  net::asio::awaitable<bool> wait_for_first_chunks();

  net::asio::steady_timer writer_wake_;
  net::asio::steady_timer reader_wake_;  // queue has room again
  net::asio::steady_timer pacing_timer_;
  net::asio::steady_timer watchdog_timer_;

  bool hello_done_ = false;
  bool closing_ = false;  // fatal error or shutdown: no more requests handled
  bool closed_ = false;
  bool write_in_flight_ = false;
  Clock::time_point started_;
  Clock::time_point last_activity_;
  Clock::time_point write_started_;
  Clock::time_point linger_deadline_ = Clock::time_point::max();
  Clock::duration linger_ = std::chrono::milliseconds(1000);

  // For the one log line per session.
  std::string models_;
  uint64_t bytes_total_ = 0;
  uint32_t streams_ = 0;
  std::string end_reason_;
  // The first stream's request read and first chunk written: the server's
  // own share of a client's time to first chunk (logged with the session).
  std::optional<Clock::time_point> first_request_read_;
  std::optional<Clock::time_point> first_chunk_written_;
  void note_first_chunk(Clock::time_point requested);
};

}  // namespace meshstream::server
