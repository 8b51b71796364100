#include "server/session.h"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "server/model_suggestions.h"

namespace meshstream::server {
namespace {

namespace asio = net::asio;
using asio::awaitable;
using asio::use_awaitable;

// Control frames queued beyond this stop the reader until the writer has
// sent some (a client that pipelines requests but does not read replies
// costs at most this much).
constexpr size_t kMaxQueuedBytes = 256 * 1024;
// After our closing frame: how long we keep draining the client's bytes so
// the close is a FIN, not a reset that could destroy the error frame
// (Session::linger_; shorter when the whole server is stopping).
constexpr auto kShutdownLinger = std::chrono::milliseconds(200);
constexpr size_t kMinChunkBytes = 1024;
constexpr size_t kMaxChunkBytes = 1 << 20;
constexpr size_t kReadBufferBytes = 2048;
// Slow start: a stream's first chunk is at most this large and each next one
// may be twice as large, up to the stream's chunk size. Under load every
// client gets its prefix and base mesh before anyone gets bulk data.
constexpr size_t kFirstChunkBytes = 8 * 1024;

std::string describe(const asio::ip::tcp::socket& socket) {
  boost::system::error_code ec;
  auto endpoint = socket.remote_endpoint(ec);
  if (ec) return "?";
  return endpoint.address().to_string() + ":" + std::to_string(endpoint.port());
}

void log_exception(std::exception_ptr e) {
  if (!e) return;
  try {
    std::rethrow_exception(e);
  } catch (const std::exception& x) {
    spdlog::error("session coroutine failed: {}", x.what());
  }
}

}  // namespace

Session::Session(net::tcp::socket socket, const ServerShared& shared, SessionRegistry& registry,
                 bool reject, bool counted)
    : socket_(std::move(socket)),
      shared_(shared),
      registry_(registry),
      reject_(reject),
      counted_(counted),
      reader_(shared.options->max_frame_bytes),
      writer_wake_(socket_.get_executor()),
      reader_wake_(socket_.get_executor()),
      pacing_timer_(socket_.get_executor()),
      watchdog_timer_(socket_.get_executor()),
      started_(Clock::now()),
      last_activity_(started_) {
  peer_ = describe(socket_);
}

Session::~Session() {
  registry_.sessions.erase(this);
  registry_.held.erase(this);
  while (starting_ > 0) started_one();
  if (counted_) --*shared_.active_sessions;
  if (stream_) shared_.metrics->count_stream(StreamOutcome::kInterrupted);
  if (reject_) --*shared_.rejecting_sessions;
  const double seconds = std::chrono::duration<double>(Clock::now() - started_).count();
  if (reject_) {
    spdlog::info("session {}: rejected (busy)", peer_);
    return;
  }
  std::string first_chunk;
  if (first_chunk_written_) {
    first_chunk = fmt::format(
        ", first chunk {:.2f} ms after its request",
        std::chrono::duration<double, std::milli>(*first_chunk_written_ - *first_request_read_)
            .count());
  }
  spdlog::info("session {}: models [{}], {} streams, {} bytes, {:.3f} s{}, ended: {}", peer_,
               models_, streams_, bytes_total_, seconds, first_chunk,
               end_reason_.empty() ? "closed" : end_reason_);
  if (first_chunk_written_ && spdlog::should_log(spdlog::level::debug)) {
    // Wall-clock times (µs since the epoch), so a load generator on the same
    // machine can split its clients' latency into the server's and its own.
    const auto wall = [&](Clock::time_point t) {
      const auto at = std::chrono::system_clock::now() - (Clock::now() - t);
      return std::chrono::duration_cast<std::chrono::microseconds>(at.time_since_epoch()).count();
    };
    spdlog::debug(
        "session {}: first stream timing: request read at {} us, first chunk written "
        "at {} us (unix)",
        peer_, wall(*first_request_read_), wall(*first_chunk_written_));
  }
}

void Session::note_first_chunk(Clock::time_point requested) {
  if (first_chunk_written_) return;
  first_request_read_ = requested;
  first_chunk_written_ = Clock::now();
}

void Session::start() {
  registry_.sessions.insert(this);
  if (!reject_) shared_.metrics->sessions_total.fetch_add(1, std::memory_order_relaxed);
  boost::system::error_code ec;
  socket_.set_option(net::tcp::no_delay(true), ec);
  auto executor = socket_.get_executor();
  asio::co_spawn(executor, read_loop(shared_from_this()), log_exception);
  asio::co_spawn(executor, write_loop(shared_from_this()), log_exception);
  asio::co_spawn(executor, watchdog(shared_from_this()), log_exception);
  if (reject_) {
    fail(v1::Error::BUSY,
         "server busy: it serves " + std::to_string(shared_.options->max_connections) +
             " connections already; retry later",
         "busy");
  }
}

void Session::shutdown() {
  linger_ = kShutdownLinger;
  if (closed_ || closing_) return;
  fail(v1::Error::SHUTTING_DOWN, "server is shutting down", "server shutdown");
}

void Session::set_end_reason(const std::string& reason) {
  if (end_reason_.empty()) end_reason_ = reason;
}

void Session::close_now(const std::string& reason) {
  set_end_reason(reason);
  if (closed_) return;
  closed_ = true;
  closing_ = true;
  boost::system::error_code ec;
  socket_.close(ec);
  writer_wake_.cancel();
  reader_wake_.cancel();
  pacing_timer_.cancel();
  watchdog_timer_.cancel();
}

void Session::push(Item item, size_t bytes) {
  queue_.push_back(std::move(item));
  queued_bytes_ += bytes;
  wake(writer_wake_);
}

void Session::send(const google::protobuf::MessageLite& message, bool closing) {
  auto bytes = std::make_shared<const std::vector<uint8_t>>(proto::encode_frame(message));
  const size_t size = bytes->size();
  push(Frame{std::move(bytes), closing}, size);
}

void Session::send_error(v1::Error::Code code, const std::string& message, bool closing) {
  v1::ServerMessage out;
  v1::Error* error = out.mutable_error();
  shared_.metrics->count_error(code);
  error->set_code(code);
  error->set_message(message);
  error->set_closing(closing);
  send(out, closing);
}

void Session::fail(v1::Error::Code code, const std::string& message,
                   const std::string& log_reason) {
  if (closing_) return;
  closing_ = true;
  set_end_reason(log_reason);
  send_error(code, message, true);
}

// ------------------------------------------------------------------ reader

awaitable<void> Session::read_loop(std::shared_ptr<Session> self) {
  std::array<uint8_t, kReadBufferBytes> buffer;
  while (!closed_) {
    while (queued_bytes_ > kMaxQueuedBytes && !closed_) {
      reader_wake_.expires_at(Clock::time_point::max());
      boost::system::error_code ignored;
      co_await reader_wake_.async_wait(asio::redirect_error(use_awaitable, ignored));
    }
    if (closed_) break;
    boost::system::error_code ec;
    const size_t n = co_await socket_.async_read_some(asio::buffer(buffer),
                                                      asio::redirect_error(use_awaitable, ec));
    if (ec) {
      close_now(ec == asio::error::eof ? "client closed" : "read failed: " + ec.message());
      break;
    }
    if (closing_) continue;  // draining until the client closes or the linger ends
    last_activity_ = Clock::now();
    reader_.feed(std::span<const uint8_t>(buffer.data(), n));
    while (!closing_) {
      auto message = reader_.next();
      if (!message) {
        const bool too_large = message.error().code == ErrorCode::kLimit;
        fail(too_large ? v1::Error::FRAME_TOO_LARGE : v1::Error::MALFORMED_FRAME,
             message.error().message,
             (too_large ? "frame too large: " : "malformed frame: ") + message.error().message);
        break;
      }
      if (!*message) break;
      handle(**message);
    }
  }
}

void Session::handle(const v1::ClientMessage& message) {
  if (!hello_done_) {
    if (message.body_case() != v1::ClientMessage::kHello) {
      fail(v1::Error::PROTOCOL_VIOLATION, "the first frame must be Hello", "no hello");
      return;
    }
    const uint32_t version = message.hello().protocol_version();
    if (version != proto::kProtocolVersion) {
      fail(v1::Error::VERSION_MISMATCH,
           "protocol version " + std::to_string(version) +
               " is not supported; this server speaks " + std::to_string(proto::kProtocolVersion),
           "wrong protocol version " + std::to_string(version));
      return;
    }
    hello_done_ = true;
    push(Frame{shared_.hello_frame}, shared_.hello_frame->size());
    return;
  }
  switch (message.body_case()) {
    case v1::ClientMessage::kHello:
      fail(v1::Error::PROTOCOL_VIOLATION, "Hello was already sent", "second hello");
      return;
    case v1::ClientMessage::kListModels: {
      // Encoded per request: states change while the server runs.
      auto frame = std::make_shared<const std::vector<uint8_t>>(
          model_list_frame(*shared_.models->snapshot()));
      const size_t size = frame->size();
      push(Frame{std::move(frame)}, size);
      return;
    }
    case v1::ClientMessage::kStream:
      handle_stream(message.stream());
      return;
    case v1::ClientMessage::kCancel:
      push(CancelStream{}, 0);
      return;
    default:
      send_error(v1::Error::INVALID_REQUEST, "empty or unknown request kind", false);
      return;
  }
}

void Session::handle_stream(const v1::StreamRequest& request) {
  const auto snapshot = shared_.models->snapshot();
  const auto found = snapshot->find(request.model());
  if (found == snapshot->end()) {
    std::vector<std::string> names;
    for (const auto& [name, status] : *snapshot) names.push_back(name);
    const std::string message =
        unknown_model_message(request.model(), closest_names(request.model(), names));
    spdlog::info("session {}: {}", peer_, message);
    send_error(v1::Error::UNKNOWN_MODEL, message, false);
    return;
  }
  const ModelStatus& status = found->second;
  // A changed file's model keeps its previous stream served while it is
  // re-encoded; only a model with no stream yet is not ready.
  std::shared_ptr<const CatalogModel> model = status.model;
  if (!model) {
    send_not_servable(status);
    return;
  }
  auto plan = plan_request(model->index, request);
  if (!plan) {
    send_error(v1::Error::INVALID_REQUEST, plan.error().message, false);
    return;
  }
  size_t chunk =
      request.max_chunk_bytes() ? request.max_chunk_bytes() : shared_.options->max_chunk_bytes;
  chunk = std::clamp(chunk, kMinChunkBytes, kMaxChunkBytes);
  if (shared_.options->rate_bytes_per_s > 0) {
    // About 20 chunks a second, so paced arrival is visibly progressive.
    chunk = std::min<size_t>(
        chunk, std::max<uint64_t>(kMinChunkBytes, shared_.options->rate_bytes_per_s / 20));
  }
  ++starting_;
  shared_.first_chunks->stream_starting(Clock::now());
  push(StartStream{.model = std::move(model),
                   .plan = *plan,
                   .chunk_bytes = chunk,
                   .requested = Clock::now(),
                   .compact_index = request.compact_index()},
       0);
}

void Session::send_not_servable(const ModelStatus& status) {
  v1::ServerMessage out;
  v1::Error* error = out.mutable_error();
  *error->mutable_model() = model_info(status);
  char progress[96];
  if (status.state == ModelState::kFailed) {
    error->set_code(v1::Error::MODEL_FAILED);
    error->set_message("model '" + status.name + "' cannot be served: " + status.reason);
  } else if (status.state == ModelState::kQueued) {
    error->set_code(v1::Error::NOT_READY);
    error->set_message("model '" + status.name +
                       "' is not ready: queued for encoding; ask again later");
  } else {
    std::snprintf(progress, sizeof progress, "%.0f %%", status.percent);
    error->set_code(v1::Error::NOT_READY);
    error->set_message("model '" + status.name + "' is not ready: encoding, " + progress +
                       (status.stage.empty() ? "" : " (" + status.stage + ")") +
                       "; ask again later");
  }
  error->set_closing(false);
  shared_.metrics->count_error(error->code());
  spdlog::info("session {}: {}", peer_, error->message());
  send(out, false);
}

// ------------------------------------------------------------------ writer

template <class Buffers>
awaitable<bool> Session::write(const Buffers& buffers) {
  write_in_flight_ = true;
  write_started_ = Clock::now();
  boost::system::error_code ec;
  co_await asio::async_write(socket_, buffers, asio::redirect_error(use_awaitable, ec));
  write_in_flight_ = false;
  if (ec) {
    close_now(closed_ ? std::string() : "write failed: " + ec.message());
    co_return false;
  }
  co_return true;
}

awaitable<bool> Session::write_end(v1::StreamEnd::Reason reason) {
  v1::ServerMessage out;
  v1::StreamEnd* end = out.mutable_end();
  end->set_reason(reason);
  end->set_bytes_sent(stream_->bytes_sent);
  end->set_end_offset(stream_->position);
  end->set_records_complete(stream_->records_complete);
  stream_.reset();
  shared_.metrics->count_stream(reason == v1::StreamEnd::COMPLETE ? StreamOutcome::kComplete
                                : reason == v1::StreamEnd::BUDGET ? StreamOutcome::kBudget
                                                                  : StreamOutcome::kCancelled);
  last_activity_ = Clock::now();
  const std::vector<uint8_t> bytes = proto::encode_frame(out);
  co_return co_await write(asio::buffer(bytes));
}

namespace {

// StreamHeader.records (proto/meshstream.proto, RecordIndex): the coded
// form computed at load when the client asked for it and the model has one,
// else the four arrays as always.
void fill_record_index(const CatalogModel& model, bool compact, v1::RecordIndex& records) {
  const StreamIndex& index = model.index;
  if (compact && !model.compact.coded.empty()) {
    records.set_coded(model.compact.coded.data(), model.compact.coded.size());
    records.set_count(static_cast<uint32_t>(index.records.size()));
    return;
  }
  const int n = static_cast<int>(index.records.size());
  records.mutable_sizes()->Reserve(n);
  records.mutable_vertices()->Reserve(n);
  records.mutable_faces()->Reserve(n);
  records.mutable_crc32()->Reserve(n);
  for (const RecordEntry& r : index.records) {
    records.add_sizes(r.size);
    records.add_vertices(r.vertices);
    records.add_faces(r.faces);
    records.add_crc32(r.crc32);
  }
}

std::vector<uint8_t> header_frame(const CatalogModel& model, const StreamPlan& plan,
                                  size_t chunk_bytes, bool compact_index) {
  const StreamIndex& index = model.index;
  const StreamHeader& h = index.header;
  v1::ServerMessage out;
  v1::StreamHeader* header = out.mutable_header();
  header->set_model(model.name);
  header->set_total_bytes(index.total_bytes());
  header->set_start_offset(plan.start);
  header->set_end_offset(plan.end);
  header->set_payload_offset(index.payload_offset);
  header->set_first_record(plan.first_record);
  header->set_end_record(plan.end_record);
  header->set_vertices(h.vertex_count);
  header->set_faces(h.face_count);
  header->set_base_vertices(h.base_vertex_count);
  header->set_base_faces(h.base_face_count);
  header->set_quant_bits(h.quant_bits);
  v1::Bounds* bounds = header->mutable_bounds();
  bounds->set_min_x(h.bounds.min.x);
  bounds->set_min_y(h.bounds.min.y);
  bounds->set_min_z(h.bounds.min.z);
  bounds->set_max_x(h.bounds.max.x);
  bounds->set_max_y(h.bounds.max.y);
  bounds->set_max_z(h.bounds.max.z);
  header->set_container_version(index.version);  // a catalog may hold older streams
  header->set_max_chunk_bytes(static_cast<uint32_t>(chunk_bytes));
  if (plan.ranged()) {
    header->set_ranged(true);
    header->set_ranged_bytes(plan.ranged_bytes);
  }
  fill_record_index(model, compact_index, *header->mutable_records());
  return proto::encode_frame(out);
}

}  // namespace

awaitable<void> Session::write_loop(std::shared_ptr<Session> self) {
  while (!closed_) {
    bool go_on = true;
    if (header_must_go_alone()) {
      go_on = co_await write_header_alone();
    } else if (!queue_.empty()) {
      go_on = co_await write_queued_item();  // control items before the stream's chunks
    } else if (stream_) {
      go_on = co_await write_stream_step();
    } else {
      co_await wait_for_work();
    }
    if (!go_on) break;
  }
}

bool Session::header_must_go_alone() const {
  return !pending_header_.empty() && (!queue_.empty() || !stream_ || stream_->all_sent());
}

awaitable<bool> Session::write_header_alone() {
  const std::vector<uint8_t> header = std::move(pending_header_);
  pending_header_.clear();
  started_one();
  co_return co_await write(asio::buffer(header));
}

awaitable<bool> Session::write_queued_item() {
  Item item = std::move(queue_.front());
  queue_.pop_front();
  if (const auto* frame = std::get_if<Frame>(&item)) co_return co_await write_frame(*frame);
  if (const auto* start = std::get_if<StartStream>(&item)) co_return co_await begin_stream(*start);
  // CancelStream. (No co_await inside || or &&: GCC 12 evaluates it anyway.)
  if (!stream_) co_return true;
  co_return co_await write_end(v1::StreamEnd::CANCELLED);
}

awaitable<bool> Session::write_frame(const Frame& frame) {
  queued_bytes_ -= frame.bytes->size();
  wake(reader_wake_);
  if (!co_await write(asio::buffer(*frame.bytes))) co_return false;
  if (frame.closing) {
    // Graceful close: FIN after our last frame, then drain what the client
    // still sends until it closes or the linger ends.
    boost::system::error_code ec;
    socket_.shutdown(net::tcp::socket::shutdown_send, ec);
    linger_deadline_ = Clock::now() + linger_;
    wake(watchdog_timer_);
    co_return false;
  }
  co_return true;
}

awaitable<bool> Session::begin_stream(const StartStream& start) {
  if (stream_) {
    if (!co_await write_end(v1::StreamEnd::CANCELLED)) co_return false;
  }
  const CatalogModel& model = *start.model;
  std::vector<ByteSegment> segments = plan_segments(model.index, start.plan);
  const uint64_t first_byte = segments.empty() ? start.plan.start : segments.front().start;
  stream_.emplace(ActiveStream{
      .model = start.model,
      .plan = start.plan,
      .segments = std::move(segments),
      .chunk_bytes = start.chunk_bytes,
      .requested = start.requested,
      .bucket = TokenBucket(double(shared_.options->rate_bytes_per_s), double(start.chunk_bytes),
                            Clock::now()),
      .position = first_byte,
      .records_complete = records_sent_at(model.index, start.plan, 0, first_byte),
  });
  ++streams_;
  if (models_.find(model.name) == std::string::npos) {
    models_ += models_.empty() ? model.name : "," + model.name;
  }
  // Sent with the first chunk (write_chunk), or alone if something else
  // must go first (write_header_alone).
  pending_header_ = header_frame(model, start.plan, start.chunk_bytes, start.compact_index);
  co_return true;
}

awaitable<bool> Session::write_stream_step() {
  ActiveStream& s = *stream_;
  if (s.all_sent()) {
    co_return co_await write_end(s.plan.ranged()   ? v1::StreamEnd::RECORDS_SENT
                                 : s.plan.complete ? v1::StreamEnd::COMPLETE
                                                   : v1::StreamEnd::BUDGET);
  }
  if (s.chunks_sent > 0) {
    // Bulk: new streams' first chunks go first (held up to the gate's
    // bound); past it, still one step back per chunk while any wait.
    if (!co_await wait_for_first_chunks()) co_return false;
    if (!queue_.empty()) co_return true;  // a request came while we waited
    if (shared_.first_chunks->starting() > 0 && !s.yielded) {
      s.yielded = true;
      co_await asio::post(socket_.get_executor(), use_awaitable);
      co_return true;
    }
  }
  s.yielded = false;
  co_return co_await write_chunk(s);
}

awaitable<bool> Session::write_chunk(ActiveStream& s) {
  const size_t limit =
      std::min(s.chunk_bytes, kFirstChunkBytes << std::min<uint32_t>(s.chunks_sent, 20));
  const ChunkCut cut = next_chunk(s.model->index, s.segments[s.segment], s.position, limit);
  const uint32_t records_complete = records_sent_at(s.model->index, s.plan, s.segment, cut.end);
  const size_t size = static_cast<size_t>(cut.end - s.position);
  // The stream header goes out with the first chunk and is paced with it,
  // so --rate behaves like a slow link (the header is most of what a
  // client waits for before its first mesh when the index is not compact).
  const auto delay = s.bucket.take(size + pending_header_.size(), Clock::now());
  if (delay > Clock::duration::zero()) {
    pacing_timer_.expires_after(delay);
    boost::system::error_code ignored;
    co_await pacing_timer_.async_wait(asio::redirect_error(use_awaitable, ignored));
    if (closed_) co_return false;
  }
  const proto::ChunkFrameHead head =
      proto::encode_chunk_frame_head(s.position, records_complete, size);
  const std::array<asio::const_buffer, 3> buffers{
      asio::buffer(pending_header_),  // empty except before the first chunk
      asio::buffer(head.bytes, head.size),
      asio::buffer(s.model->stream().data() + s.position, size)};
  if (s.chunks_sent == 0) note_first_chunk(s.requested);
  if (!pending_header_.empty()) started_one();
  const bool written = co_await write(buffers);
  pending_header_.clear();
  if (!written) co_return false;
  // Only the writer replaces stream_, so `s` is the stream just written.
  s.position = cut.end;
  s.bytes_sent += size;
  s.records_complete = records_complete;
  if (s.position >= s.segments[s.segment].end && s.segment + 1 < s.segments.size()) {
    ++s.segment;  // the next range starts where its first record is
    s.position = s.segments[s.segment].start;
  }
  ++s.chunks_sent;
  bytes_total_ += size;
  shared_.metrics->bytes_sent.fetch_add(size, std::memory_order_relaxed);
  co_return true;
}

awaitable<void> Session::wait_for_work() {
  writer_wake_.expires_at(Clock::time_point::max());
  boost::system::error_code ignored;
  co_await writer_wake_.async_wait(asio::redirect_error(use_awaitable, ignored));
}

awaitable<bool> Session::wait_for_first_chunks() {
  while (!closed_) {
    const auto until = shared_.first_chunks->hold_bulk_until(Clock::now());
    if (!until || !queue_.empty()) co_return true;
    // Woken by the deadline, by the gate (release_bulk) or by push().
    registry_.held.insert(this);
    writer_wake_.expires_at(*until);
    boost::system::error_code ignored;
    co_await writer_wake_.async_wait(asio::redirect_error(use_awaitable, ignored));
    registry_.held.erase(this);
  }
  co_return false;
}

void SessionRegistry::release_held() {
  // release_bulk only cancels a timer (no handler runs here), so `held`
  // does not change while we walk it.
  for (Session* s : held) s->release_bulk();
}

// ---------------------------------------------------------------- watchdog

awaitable<void> Session::watchdog(std::shared_ptr<Session> self) {
  const ServerOptions& o = *shared_.options;
  // Re-check at least this often: state changes (a write starting) do not
  // wake the watchdog, so a wait never lasts longer than this.
  const auto check = std::max<Clock::duration>(
      std::chrono::milliseconds(5),
      std::min({o.handshake_timeout, o.idle_timeout, o.stall_timeout}) / 4);
  while (!closed_) {
    const auto now = Clock::now();
    if (now >= linger_deadline_) {
      close_now("");
      break;
    }
    if (write_in_flight_ && now - write_started_ >= o.stall_timeout) {
      close_now("stalled: client did not read for " + std::to_string(o.stall_timeout.count()) +
                " ms");
      break;
    }
    if (!closing_) {
      if (!hello_done_ && now - started_ >= o.handshake_timeout) {
        fail(v1::Error::TIMEOUT,
             "no Hello within " + std::to_string(o.handshake_timeout.count()) + " ms",
             "handshake timeout");
      } else if (hello_done_ && !stream_ && queue_.empty() && !write_in_flight_ &&
                 now - last_activity_ >= o.idle_timeout) {
        fail(v1::Error::TIMEOUT, "idle for " + std::to_string(o.idle_timeout.count()) + " ms",
             "idle timeout");
      }
    }
    auto next = now + check;
    if (linger_deadline_ < next) next = linger_deadline_;
    watchdog_timer_.expires_at(next);
    boost::system::error_code ignored;
    co_await watchdog_timer_.async_wait(asio::redirect_error(use_awaitable, ignored));
  }
}

}  // namespace meshstream::server
