#include "client/stream_client.h"

#include <algorithm>
#include <thread>

#include "common/cli/version.h"

namespace meshstream::client {

using Clock = std::chrono::steady_clock;

void RateMeter::add(uint64_t bytes, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  if (!first_) {
    first_ = now;
    return;
  }
  samples_.emplace_back(now, bytes);
  while (!samples_.empty() && now - samples_.front().first > window_) samples_.pop_front();
}

double RateMeter::bytes_per_s(Clock::time_point now) const {
  std::lock_guard lock(mutex_);
  if (!first_ || now <= *first_) return 0;
  const Clock::time_point from = std::max(*first_, now - window_);
  uint64_t sum = 0;
  for (const auto& [t, b] : samples_) {
    if (t > from && t <= now) sum += b;
  }
  const double seconds = std::chrono::duration<double>(now - from).count();
  return seconds > 0 ? static_cast<double>(sum) / seconds : 0;
}

namespace {

// The server's own message first (it names the model, the value, a
// suggestion), then who said it and the protocol code.
std::string server_error_text(const std::string& peer, const v1::Error& e) {
  return "server " + peer + ": " + e.message() + " [" + v1::Error_Code_Name(e.code()) + "]";
}

}  // namespace

const char* model_state_name(v1::ModelInfo::State state) {
  switch (state) {
    case v1::ModelInfo::ENCODING:
      return "encoding";
    case v1::ModelInfo::QUEUED:
      return "queued";
    case v1::ModelInfo::FAILED:
      return "failed";
    default:
      return "ready";
  }
}

namespace {

// A Connection error's reason without its "server PEER " lead-in.
std::string reason_only(const std::string& message, const std::string& peer) {
  const std::string lead = "server " + peer + " ";
  return message.rfind(lead, 0) == 0 ? message.substr(lead.size()) : message;
}

// Errors after which trying again later may succeed.
bool transient(v1::Error::Code code) {
  switch (code) {
    case v1::Error::BUSY:
    case v1::Error::SHUTTING_DOWN:
    case v1::Error::TIMEOUT:
    case v1::Error::INTERNAL:
      return true;
    default:
      return false;
  }
}

v1::Budget to_proto(const Budget& b) {
  v1::Budget out;
  switch (b.kind) {
    case Budget::Kind::kAll:
      break;
    case Budget::Kind::kBytes:
      out.set_bytes(static_cast<uint64_t>(b.value));
      break;
    case Budget::Kind::kVertices:
      out.set_vertices(static_cast<uint32_t>(b.value));
      break;
    case Budget::Kind::kPercentVertices:
      out.set_percent_vertices(b.value);
      break;
    case Budget::Kind::kPercentBytes:
      out.set_percent(b.value);
      break;
    case Budget::Kind::kRatio:  // no wire form and no client option: the nearest percent
      out.set_percent(100.0 / b.value);
      break;
  }
  return out;
}

}  // namespace

Status handshake(Connection& connection, Millis timeout, bool* server_answered) {
  if (server_answered) *server_answered = false;
  const std::string peer = connection.peer();
  v1::ClientMessage hello;
  hello.mutable_hello()->set_protocol_version(proto::kProtocolVersion);
  hello.mutable_hello()->set_client_name(cli::version_line("meshstream-client"));
  if (auto s = connection.send(hello, timeout); !s) return s;
  auto reply = connection.receive(timeout);
  if (!reply) {
    return make_error(reply.error().code, "no meshstream server at " + peer +
                                              " (no answer to Hello: it " +
                                              reason_only(reply.error().message, peer) + ")");
  }
  if (reply->has_error()) {
    if (server_answered) *server_answered = true;
    // kUnsupported marks an answer that retrying will not change.
    const ErrorCode code =
        transient(reply->error().code()) ? ErrorCode::kIo : ErrorCode::kUnsupported;
    return make_error(code, server_error_text(peer, reply->error()));
  }
  if (!reply->has_hello()) {
    return make_error(ErrorCode::kParse, "no meshstream server at " + peer +
                                             " (it did not answer Hello with ServerHello)");
  }
  if (server_answered) *server_answered = true;
  if (reply->hello().protocol_version() != proto::kProtocolVersion) {
    return make_error(ErrorCode::kUnsupported,
                      "server speaks protocol version " +
                          std::to_string(reply->hello().protocol_version()) + ", this client " +
                          std::to_string(proto::kProtocolVersion));
  }
  return {};
}

Result<std::vector<v1::ModelInfo>> list_models(const std::string& host, uint16_t port,
                                               Millis timeout) {
  auto connection = Connection::open(host, port, timeout);
  if (!connection) return tl::unexpected(connection.error());
  if (auto s = handshake(**connection, timeout); !s) return tl::unexpected(s.error());
  v1::ClientMessage request;
  request.mutable_list_models();
  if (auto s = (*connection)->send(request, timeout); !s) return tl::unexpected(s.error());
  while (true) {
    auto reply = (*connection)->receive(timeout);
    if (!reply) return tl::unexpected(reply.error());
    if (reply->has_error())
      return make_error(ErrorCode::kIo, server_error_text((*connection)->peer(), reply->error()));
    if (reply->has_model_list()) {
      return std::vector<v1::ModelInfo>(reply->model_list().models().begin(),
                                        reply->model_list().models().end());
    }
  }
}

void StreamClient::stop() {
  stop_ = true;
  pause_changed_.notify_all();
}

void StreamClient::pause() { paused_ = true; }

void StreamClient::resume() {
  paused_ = false;
  pause_changed_.notify_all();
}

bool StreamClient::wait_while_paused() {
  std::unique_lock lock(pause_mutex_);
  pause_changed_.wait(lock, [&] { return stop_.load() || !paused_.load(); });
  return !stop_.load();
}

StreamClient::Attempt StreamClient::attempt(
    DecodedStream& decoded, const std::function<void(const StreamFacts&)>& on_header,
    bool& progressed, Error& error) {
  const ReconnectPolicy& policy = target_.reconnect;
  auto connection = Connection::open(target_.host, target_.port, policy.connect_timeout, &stop_);
  if (!connection) {
    error = connection.error();
    // Nothing to resume: a first connection that cannot be made is the
    // address's fault (wrong port, a name that does not resolve).
    return handshaken_ ? Attempt::kRetry : Attempt::kFatal;
  }
  Connection& c = **connection;
  bool server_answered = false;
  if (auto s = handshake(c, policy.connect_timeout, &server_answered); !s) {
    error = s.error();
    if (s.error().code == ErrorCode::kUnsupported) return Attempt::kFatal;
    // A server that answered "busy" (or the like) asks to be tried again; a
    // peer that never spoke the protocol will not start to. A peer that
    // closed before sending a byte may be a load balancer whose server just
    // died (HAProxy in TCP mode accepts first, then connects): retried a
    // few times (docs/deploy.md).
    if (!handshaken_ && !server_answered && c.bytes_read() == 0 && c.peer_closed() &&
        ++silent_first_closes_ <= kSilentFirstCloseRetries) {
      return Attempt::kRetry;
    }
    return handshaken_ || server_answered ? Attempt::kRetry : Attempt::kFatal;
  }
  handshaken_ = true;
  v1::ClientMessage request;
  v1::StreamRequest& r = *request.mutable_stream();
  r.set_model(target_.model);
  const uint64_t resume = decoded.records_decoded() > 0 ? decoded.resume_offset() : 0;
  r.set_resume_offset(resume);
  *r.mutable_budget() = to_proto(target_.budget);
  r.set_max_chunk_bytes(target_.max_chunk_bytes);
  // The small coded index (~1.5 bytes a record instead of ~12) gets the
  // first mesh out sooner; either form of the answer is read.
  r.set_compact_index(true);
  if (auto s = c.send(request, policy.connect_timeout); !s) {
    error = s.error();
    return Attempt::kRetry;
  }

  bool have_header = false;
  uint64_t expected = 0;  // stream offset of the next chunk
  while (true) {
    if (paused_ && !wait_while_paused()) break;
    if (stop_) break;
    auto message = c.receive(policy.read_timeout, &stop_);
    if (stop_) break;
    if (!message) {
      error = message.error();
      return Attempt::kRetry;
    }
    if (message->has_error()) {
      const v1::Error& e = message->error();
      if (e.code() == v1::Error::NOT_READY && target_.wait && !have_header) {
        // --wait: ask again in a while, on this connection (each request
        // keeps it from idling out).
        if (on_waiting_) on_waiting_(e.model());
        {
          std::unique_lock lock(pause_mutex_);
          pause_changed_.wait_for(lock, target_.wait_poll, [&] { return stop_.load(); });
        }
        if (stop_) break;
        if (auto s = c.send(request, policy.connect_timeout); !s) {
          error = s.error();
          return Attempt::kRetry;
        }
        continue;
      }
      error = Error{ErrorCode::kIo, server_error_text(c.peer(), e)};
      // Resuming a stream after a lost connection: a server that restarted
      // may still be loading the model (from its cache); try again.
      if (e.code() == v1::Error::NOT_READY && facts_) return Attempt::kRetry;
      if (e.code() == v1::Error::NOT_READY) error.message += " (--wait waits until it is ready)";
      return transient(e.code()) ? Attempt::kRetry : Attempt::kFatal;
    }
    if (message->has_header()) {
      const v1::StreamHeader& h = message->header();
      auto facts = facts_from_header(h);
      if (!facts) {
        error = facts.error();
        return Attempt::kFatal;
      }
      if (facts_ && (facts->total_bytes != facts_->total_bytes ||
                     facts->records_total != facts_->records_total)) {
        error = Error{ErrorCode::kCorrupt,
                      "model '" + target_.model + "' changed on the server between connections"};
        return Attempt::kFatal;
      }
      if (!facts_) {
        if (check_header_) {
          if (Status checked = check_header_(*facts); !checked) {
            error = checked.error();
            return Attempt::kFatal;
          }
        }
        facts_ = std::move(*facts);
        if (on_header) on_header(*facts_);
      }
      if (auto s = decoded.resume_at(h.start_offset()); !s) {
        error = s.error();
        return Attempt::kFatal;
      }
      expected = h.start_offset();
      have_header = true;
      continue;
    }
    if (message->has_chunk()) {
      const v1::Chunk& chunk = message->chunk();
      if (!have_header || chunk.offset() != expected) {
        error = Error{ErrorCode::kParse, "server sent a chunk at offset " +
                                             std::to_string(chunk.offset()) + ", expected " +
                                             std::to_string(expected)};
        return Attempt::kRetry;
      }
      const std::string& data = chunk.data();
      rate_.add(data.size());
      const auto* bytes = reinterpret_cast<const uint8_t*>(data.data());
      const uint64_t end = expected + data.size();
      const uint32_t before = decoded.records_decoded();
      // Feed record by record so each record is its own update.
      uint64_t at = expected;
      const auto& ends = facts_->record_end;
      while (at < end) {
        auto next = std::upper_bound(ends.begin(), ends.end(), at);
        const uint64_t stop_at = next == ends.end() ? end : std::min(end, *next);
        auto fed = decoded.feed(std::span<const uint8_t>(bytes + (at - expected), stop_at - at));
        if (!fed) {
          error = fed.error();
          // A record that fails its checksum was altered on the way; it is
          // fetched again from the last good record. Anything else in the
          // stream itself is the stream's fault and final.
          return decoded.error_is_recoverable() ? Attempt::kRetry : Attempt::kFatal;
        }
        at = stop_at;
        decoded.set_bytes_received(at);
      }
      expected = end;
      if (decoded.records_decoded() > before) progressed = true;
      // The header repeats the stream's own index: they must agree, or the
      // records counted and resumed from would not be the stream's.
      if (!index_checked_) {
        if (auto summary = decoded.index_summary()) {
          index_checked_ = true;
          if (summary->first != facts_->total_bytes || summary->second != facts_->records_total) {
            error = Error{ErrorCode::kCorrupt,
                          "model '" + target_.model + "': the server's header announces " +
                              std::to_string(facts_->records_total) + " records and " +
                              std::to_string(facts_->total_bytes) +
                              " bytes, the stream's own index " + std::to_string(summary->second) +
                              " records and " + std::to_string(summary->first) + " bytes"};
            return Attempt::kFatal;
          }
        }
      }
      continue;
    }
    if (message->has_end()) {
      const v1::StreamEnd& e = message->end();
      if (e.reason() == v1::StreamEnd::CANCELLED) {
        error = Error{ErrorCode::kIo, "server cancelled the stream"};
        return Attempt::kRetry;
      }
      StreamOutcome outcome;
      outcome.reason = e.reason() == v1::StreamEnd::BUDGET ? "budget" : "complete";
      decoded.finish(outcome);
      return Attempt::kDone;
    }
    // ModelList, ServerHello or a case this client does not know: ignore.
  }
  StreamOutcome cancelled;
  cancelled.reason = "cancelled";
  decoded.finish(cancelled);
  return Attempt::kDone;
}

void run_attempts(DecodedStream& decoded, const ReconnectPolicy& policy,
                  const std::atomic<bool>& stop, std::mutex& mutex, std::condition_variable& wake,
                  std::atomic<int>& reconnects,
                  const std::function<void(const Error&, int attempt)>& on_retry,
                  const std::function<AttemptEnd(bool& progressed, Error& error)>& attempt) {
  int failures = 0;
  while (!stop) {
    bool progressed = false;
    Error error{ErrorCode::kIo, ""};
    const AttemptEnd a = attempt(progressed, error);
    if (a == AttemptEnd::kDone) return;
    if (stop) break;  // stop() (Ctrl-C) cut the attempt short: not its error
    if (a == AttemptEnd::kFatal) {
      decoded.finish(StreamOutcome{false, "error", error});
      return;
    }
    if (progressed) failures = 0;
    if (++failures > policy.max_attempts) {
      error.message =
          "giving up after " + std::to_string(policy.max_attempts) + " attempts: " + error.message;
      decoded.finish(StreamOutcome{false, "error", error});
      return;
    }
    ++reconnects;
    if (on_retry) on_retry(error, failures);
    // Bounded exponential back-off, interruptible by stop().
    const auto delay =
        std::min<Millis>(policy.max_delay, policy.first_delay * (1 << std::min(failures - 1, 16)));
    std::unique_lock lock(mutex);
    wake.wait_for(lock, delay, [&] { return stop.load(); });
  }
  StreamOutcome cancelled;
  cancelled.reason = "cancelled";
  decoded.finish(cancelled);
}

void StreamClient::run(DecodedStream& decoded,
                       const std::function<void(const StreamFacts&)>& on_header) {
  run_attempts(decoded, target_.reconnect, stop_, pause_mutex_, pause_changed_, reconnects_,
               on_retry_, [&](bool& progressed, Error& error) {
                 return attempt(decoded, on_header, progressed, error);
               });
}

}  // namespace meshstream::client
