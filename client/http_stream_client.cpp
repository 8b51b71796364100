#include "client/http_stream_client.h"

#include <algorithm>
#include <cstdio>

#include "client/tcp_link.h"
#include "common/codec/container.h"
#include "common/codec/decoder.h"

namespace meshstream::client {

namespace {

// HOST:PORT as a URL writes it ("[::1]:8080" for IPv6), for messages.
std::string url_peer(const std::string& host, uint16_t port) {
  return (host.find(':') != std::string::npos ? "[" + host + "]" : host) + ":" +
         std::to_string(port);
}

// Reads some body bytes: 0 when the server closed the connection; kIo
// when nothing came for `timeout`, the connection broke, or a stop.
Result<size_t> read_some(TcpLink& link, std::span<uint8_t> into, Millis timeout,
                         const std::atomic<bool>* stop) {
  const auto [got, error] = link.read_some(into, timeout, stop);
  if (got > 0) return got;
  if (error == net::asio::error::eof) return size_t{0};
  if (error == net::asio::error::timed_out) {
    return make_error(ErrorCode::kIo, "server " + link.peer() + " sent nothing for " +
                                          std::to_string(timeout.count()) + " ms");
  }
  if (error) {
    return make_error(ErrorCode::kIo,
                      "server " + link.peer() + " broke the connection: " + error.message());
  }
  return got;
}

// The first bytes of a body that is not a stream, for the message.
std::string describe_start(std::span<const uint8_t> bytes) {
  std::string hex, text;
  for (size_t i = 0; i < std::min<size_t>(bytes.size(), 8); ++i) {
    char b[4];
    std::snprintf(b, sizeof b, "%02x ", bytes[i]);
    hex += b;
    text += (bytes[i] >= 32 && bytes[i] < 127) ? static_cast<char>(bytes[i]) : '.';
  }
  if (!hex.empty()) hex.pop_back();
  return hex + " '" + text + "'";
}

bool starts_like_html(std::span<const uint8_t> bytes) {
  std::string s;
  for (size_t i = 0; i < std::min<size_t>(bytes.size(), 64); ++i)
    s += static_cast<char>(std::tolower(bytes[i]));
  const size_t at = s.find_first_not_of(" \t\r\n");
  return at != std::string::npos &&
         (s.compare(at, 5, "<html") == 0 || s.compare(at, 9, "<!doctype") == 0 ||
          s.compare(at, 5, "<head") == 0 || s.compare(at, 5, "<body") == 0);
}

// The facts a meshstream server's header would carry, from the stream's own
// index; the budget's last record by the server's rule (stream_plan.cpp:
// prefix_for_budget realigned to whole records, at least the base mesh).
StreamFacts facts_from_index(const StreamIndex& index, const std::string& model,
                             const Budget& budget) {
  StreamFacts f;
  f.model = model;
  f.total_bytes = index.total_bytes();
  f.payload_offset = index.payload_offset;
  f.records_total = static_cast<uint32_t>(index.records.size());
  f.vertices = index.header.vertex_count;
  f.faces = index.header.face_count;
  f.base_vertices = index.header.base_vertex_count;
  f.base_faces = index.header.base_face_count;
  f.quant_bits = index.header.quant_bits;
  for (const RecordEntry& e : index.records) {
    f.record_end.push_back(e.offset + e.size);
    f.record_vertices.push_back(e.vertices);
    f.record_faces.push_back(e.faces);
  }
  uint32_t end_record = f.records_total;
  if (budget.kind != Budget::Kind::kAll) {
    const uint64_t bytes = prefix_for_budget(index, budget);
    const auto within = std::upper_bound(f.record_end.begin(), f.record_end.end(), bytes);
    end_record = std::max<uint32_t>(1, static_cast<uint32_t>(within - f.record_end.begin()));
  }
  f.end_record = end_record;
  f.end_offset = f.record_end[end_record - 1];
  return f;
}

}  // namespace

HttpStreamClient::HttpStreamClient(HttpTarget target)
    : target_(std::move(target)), buffer_(256 * 1024) {
  if (target_.range_bytes == 0) target_.range_bytes = kHttpDefaultRangeBytes;
}
HttpStreamClient::~HttpStreamClient() = default;

void HttpStreamClient::stop() {
  stop_ = true;
  pause_changed_.notify_all();
}

void HttpStreamClient::resume() {
  paused_ = false;
  pause_changed_.notify_all();
}

bool HttpStreamClient::wait_while_paused() {
  std::unique_lock lock(pause_mutex_);
  pause_changed_.wait(lock, [&] { return stop_.load() || !paused_.load(); });
  return !stop_.load();
}

std::optional<uint64_t> HttpStreamClient::request_end() const {
  if (!facts_) return next_ + std::max<uint64_t>(target_.probe_bytes, 64) - 1;
  // Whole records, at least range_bytes of them, up to the budget's end.
  const auto& ends = facts_->record_end;
  const uint64_t want = next_ + target_.range_bytes;
  auto it = std::lower_bound(ends.begin(), ends.begin() + facts_->end_record, want);
  const uint64_t end = it == ends.begin() + facts_->end_record ? facts_->end_offset : *it;
  return std::min(end, facts_->end_offset) - 1;
}

Status HttpStreamClient::read_index(DecodedStream& decoded,
                                    const std::function<void(const StreamFacts&)>& on_header) {
  const std::string& url = target_.url.text;
  if (prefix_.size() >= 4 && !std::equal(prefix_.begin(), prefix_.begin() + 4, kContainerMagic)) {
    refusal_ = Attempt::kFatal;
    const std::string what = starts_like_html(prefix_) ? "an HTML page" : "not an .hcs stream";
    return make_error(ErrorCode::kParse, url + ": the body is " + what + " (it starts with " +
                                             describe_start(prefix_) +
                                             ", an .hcs stream with 'MHCS')");
  }
  auto index = read_stream_index(prefix_);
  if (!index) {
    if (index.error().code == ErrorCode::kTruncated) return {};  // more bytes, please
    // A damaged checksum may be bytes altered on the way: fetched again.
    refusal_ = index.error().code == ErrorCode::kCorrupt ? Attempt::kRetry : Attempt::kFatal;
    return make_error(index.error().code,
                      url + ": not a readable .hcs stream: " + index.error().message);
  }
  if (total_ && *total_ != index->total_bytes()) {
    refusal_ = Attempt::kFatal;
    return make_error(ErrorCode::kCorrupt, url + ": the file holds " + std::to_string(*total_) +
                                               " bytes but its index describes " +
                                               std::to_string(index->total_bytes()));
  }
  StreamFacts facts = facts_from_index(*index, target_.url.model, target_.budget);
  if (check_header_) {
    if (Status checked = check_header_(facts); !checked) {
      refusal_ = Attempt::kFatal;
      return checked;
    }
  }
  facts_ = std::move(facts);
  if (on_header) on_header(*facts_);
  if (auto s = decoded.resume_at(0); !s) {
    refusal_ = Attempt::kFatal;
    return s;
  }
  std::vector<uint8_t> bytes;
  bytes.swap(prefix_);
  next_ = 0;
  return feed_records(decoded, bytes);
}

Status HttpStreamClient::feed_records(DecodedStream& decoded, std::span<const uint8_t> bytes) {
  // Only up to the budget's end; each record its own update (as over TCP).
  const uint64_t end = std::min<uint64_t>(next_ + bytes.size(), facts_->end_offset);
  const auto& ends = facts_->record_end;
  uint64_t at = next_;
  while (at < end) {
    auto record_end = std::upper_bound(ends.begin(), ends.end(), at);
    const uint64_t stop_at = record_end == ends.end() ? end : std::min(end, *record_end);
    auto fed = decoded.feed(bytes.subspan(at - next_, stop_at - at));
    if (!fed) {
      // A record that fails its checksum was altered on the way: fetched
      // again from the last good record. Anything else is the stream's.
      refusal_ = decoded.error_is_recoverable() ? Attempt::kRetry : Attempt::kFatal;
      return tl::unexpected(Error{fed.error().code, target_.url.text + ": " + fed.error().message});
    }
    at = stop_at;
    decoded.set_bytes_received(at);
  }
  next_ = at;
  return {};
}

Status HttpStreamClient::accept(DecodedStream& decoded,
                                const std::function<void(const StreamFacts&)>& on_header,
                                uint64_t offset, std::span<const uint8_t> bytes) {
  // A whole-file body repeats what arrived before a resume: skip it.
  if (offset + bytes.size() <= next_) return {};
  if (offset < next_) bytes = bytes.subspan(next_ - offset);
  if (complete() || bytes.empty()) return {};
  if (!facts_) {
    const size_t limit = 64u << 20;  // a header and index larger than any stream has
    prefix_.insert(prefix_.end(), bytes.begin(), bytes.end());
    next_ += bytes.size();
    if (prefix_.size() > limit) {
      refusal_ = Attempt::kFatal;
      return make_error(ErrorCode::kLimit, target_.url.text + ": no .hcs index in the first " +
                                               std::to_string(limit) + " bytes");
    }
    return read_index(decoded, on_header);
  }
  return feed_records(decoded, bytes);
}

HttpStreamClient::Attempt HttpStreamClient::exchange(
    DecodedStream& decoded, const std::function<void(const StreamFacts&)>& on_header,
    Error& error) {
  const ReconnectPolicy& policy = target_.reconnect;
  const std::string& url = target_.url.text;
  // A server known to ignore Range gets a plain GET (its answer is the whole file).
  const uint64_t first = next_;
  const std::optional<uint64_t> last = range_ignored_ ? std::nullopt : request_end();
  const std::string request = range_request(target_.url, range_ignored_ ? 0 : first, last);
  if (const auto e = link_->write_all(
          std::span(reinterpret_cast<const uint8_t*>(request.data()), request.size()),
          policy.connect_timeout)) {
    error = Error{ErrorCode::kIo, "sending to " + link_->peer() + " failed: " + e.message()};
    return Attempt::kRetry;
  }
  ++requests_;
  ++link_requests_;
  std::optional<BodyPlan> plan;
  uint64_t body_at = 0;  // stream offset of the next body byte
  refusal_.reset();
  auto on_head = [&](const HttpResponseHead& head) -> Status {
    auto checked = check_response(head, url, first, last, total_);
    if (!checked) {
      refusal_ = checked.error().code == ErrorCode::kIo ? Attempt::kRetry : Attempt::kFatal;
      return tl::unexpected(checked.error());
    }
    plan = *checked;
    if (plan->whole) range_ignored_ = true;
    if (plan->total) total_ = plan->total;
    body_at = plan->stream_offset;
    answered_ = true;
    return {};
  };
  auto on_body = [&](std::span<const uint8_t> bytes) -> Status {
    if (plan->length && body_at + bytes.size() > plan->stream_offset + *plan->length) {
      refusal_ = Attempt::kFatal;
      return make_error(ErrorCode::kParse, url + ": the body is longer than its Content-Range");
    }
    rate_.add(bytes.size());
    const uint64_t at = body_at;
    body_at += bytes.size();
    return accept(decoded, on_header, at, bytes);
  };
  HttpResponseReader reader(HttpLimits{}, on_head, on_body);
  auto fail = [&](const Error& e) {
    error = e;
    link_.reset();  // the connection's state is unknown now
    return refusal_.value_or(Attempt::kFatal);
  };
  // Parses `bytes`; an outcome when the exchange is over.
  auto parse = [&](std::span<const uint8_t> bytes) -> std::optional<Attempt> {
    if (Status s = reader.feed(bytes); !s) {
      // The callbacks' errors name the URL already; the parser's do not.
      return fail(refusal_ ? s.error() : Error{s.error().code, url + ": " + s.error().message});
    }
    if (reader.done()) {
      if (plan->length && body_at != plan->stream_offset + *plan->length) {
        return fail(Error{ErrorCode::kParse, url + ": the body is shorter than announced"});
      }
      const auto rest = reader.leftover();
      leftover_.assign(rest.begin(), rest.end());
      if (!reader.head().keep_alive) link_.reset();
      return Attempt::kDone;
    }
    // Everything the budget needs is here: a whole-file body is not read on.
    if (complete()) {
      link_.reset();
      return Attempt::kDone;
    }
    return std::nullopt;
  };
  std::vector<uint8_t> pending;
  pending.swap(leftover_);
  if (!pending.empty()) {
    if (auto outcome = parse(pending)) return *outcome;
  }
  while (true) {
    if (paused_ && !wait_while_paused()) return Attempt::kDone;
    if (stop_) return Attempt::kDone;
    auto got = read_some(*link_, buffer_, policy.read_timeout, &stop_);
    if (stop_) return Attempt::kDone;
    if (!got) {
      refusal_ = Attempt::kRetry;
      return fail(Error{got.error().code, url + ": " + got.error().message});
    }
    if (*got == 0) {
      if (!reader.head_done() && reader.body_bytes() == 0 && link_requests_ > 1) {
        // A kept-alive connection the server had closed meanwhile (its idle
        // timeout): not a loss, ask again on a new one.
        link_.reset();
        stale_link_ = true;
        return Attempt::kDone;
      }
      if (Status s = reader.end_of_input(); !s) {
        refusal_ = Attempt::kRetry;  // a dropped connection: resumed
        return fail(Error{s.error().code, url + ": " + s.error().message});
      }
      link_.reset();
      return Attempt::kDone;
    }
    if (auto outcome = parse(std::span<const uint8_t>(buffer_.data(), *got))) return *outcome;
  }
}

HttpStreamClient::Attempt HttpStreamClient::attempt(
    DecodedStream& decoded, const std::function<void(const StreamFacts&)>& on_header,
    bool& progressed, Error& error) {
  const ReconnectPolicy& policy = target_.reconnect;
  // Resume from the last good record (from 0 before the base mesh).
  next_ = decoded.records_decoded() > 0 ? decoded.resume_offset() : 0;
  prefix_.clear();
  if (auto s = decoded.resume_at(next_); !s) {
    error = s.error();
    return Attempt::kFatal;
  }
  while (!stop_) {
    if (complete()) {
      StreamOutcome outcome;
      outcome.reason = facts_->end_offset == facts_->total_bytes ? "complete" : "budget";
      decoded.finish(outcome);
      return Attempt::kDone;
    }
    if (!link_) {
      leftover_.clear();
      auto link = TcpLink::open(target_.url.host, target_.url.port,
                                url_peer(target_.url.host, target_.url.port),
                                policy.connect_timeout, &stop_);
      if (!link) {
        error = Error{link.error().code, target_.url.text + ": " + link.error().message};
        // Nothing to resume: a first connection that cannot be made is the URL's fault.
        return answered_ ? Attempt::kRetry : Attempt::kFatal;
      }
      link_ = std::move(*link);
      link_requests_ = 0;
    }
    const uint32_t before = decoded.records_decoded();
    const uint64_t at = next_;
    const Attempt a = exchange(decoded, on_header, error);
    if (decoded.records_decoded() > before) progressed = true;
    if (a != Attempt::kDone) return a;
    if (stop_) break;
    if (stale_link_) {
      stale_link_ = false;  // the next request goes out on a new connection
      continue;
    }
    if (next_ == at && !complete()) {
      // A response that ended without a byte of what was asked: asking
      // again would loop.
      error = Error{ErrorCode::kParse, target_.url.text + ": the response to a request for bytes " +
                                           std::to_string(at) + "- carried none of them"};
      return Attempt::kFatal;
    }
  }
  StreamOutcome cancelled;
  cancelled.reason = "cancelled";
  decoded.finish(cancelled);
  return Attempt::kDone;
}

void HttpStreamClient::run(DecodedStream& decoded,
                           const std::function<void(const StreamFacts&)>& on_header) {
  run_attempts(decoded, target_.reconnect, stop_, pause_mutex_, pause_changed_, reconnects_,
               on_retry_, [&](bool& progressed, Error& error) {
                 return attempt(decoded, on_header, progressed, error);
               });
}

}  // namespace meshstream::client
