// The HTTP source of a stream: an `.hcs` file on any web server, read with
// HTTP/1.1 range requests on one keep-alive connection. First the header
// and index (a 64 KiB range, more if the index is longer), from which the
// facts a meshstream server would send are computed here (records, their
// ends and counts, the budget's last record, by the decoder's own rule);
// then the records in stream order, several per request (--max-chunk-bytes,
// default 256 KiB a request, always whole records). Losing the connection
// resumes with a range from the last good record; a record that fails its
// checksum is fetched again; both within ReconnectPolicy's bounded back-off.
// A server that ignores Range (200 and the whole file) is read once,
// progressively, up to the budget, and never asked again with a range it
// ignores. 404s, HTML pages and bodies that are not `.hcs` streams end the
// run with an error naming the URL and the problem.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "client/decoded_stream.h"
#include "client/http_response.h"
#include "client/stream_client.h"
#include "client/stream_facts.h"
#include "common/codec/budget.h"

namespace meshstream::client {

class TcpLink;

inline constexpr uint64_t kHttpPrefixProbeBytes = 64 * 1024;
inline constexpr uint64_t kHttpDefaultRangeBytes = 256 * 1024;

struct HttpTarget {
  HttpUrl url;
  Budget budget;
  uint64_t range_bytes = 0;  // bytes per range request (0 = kHttpDefaultRangeBytes)
  // The first request, before the index is known (the size of the header
  // and index is not known either; what follows them is the base mesh).
  uint64_t probe_bytes = kHttpPrefixProbeBytes;
  ReconnectPolicy reconnect;
};

class HttpStreamClient {
 public:
  explicit HttpStreamClient(HttpTarget target);
  ~HttpStreamClient();

  void run(DecodedStream& decoded, const std::function<void(const StreamFacts&)>& on_header);
  void check_header(std::function<Status(const StreamFacts&)> check) {
    check_header_ = std::move(check);
  }
  void on_retry(std::function<void(const Error&, int attempt)> f) { on_retry_ = std::move(f); }
  void stop();
  void pause() { paused_ = true; }
  void resume();
  bool paused() const { return paused_.load(); }
  double rate_bytes_per_s() const { return rate_.bytes_per_s(); }
  int reconnects() const { return reconnects_.load(); }
  // Range requests sent so far, and whether the server ignored Range.
  uint64_t requests() const { return requests_; }
  bool range_ignored() const { return range_ignored_; }

 private:
  using Attempt = AttemptEnd;
  Attempt attempt(DecodedStream& decoded, const std::function<void(const StreamFacts&)>& on_header,
                  bool& progressed, Error& error);
  // One request and its response: [next_, last] (`last` nullopt: to the end).
  Attempt exchange(DecodedStream& decoded, const std::function<void(const StreamFacts&)>& on_header,
                   Error& error);
  // Body bytes at stream offset `offset` (skips what is before next_,
  // drops what is past the budget's end).
  Status accept(DecodedStream& decoded, const std::function<void(const StreamFacts&)>& on_header,
                uint64_t offset, std::span<const uint8_t> bytes);
  Status read_index(DecodedStream& decoded,
                    const std::function<void(const StreamFacts&)>& on_header);
  Status feed_records(DecodedStream& decoded, std::span<const uint8_t> bytes);
  std::optional<uint64_t> request_end() const;  // inclusive last byte of the next request
  bool complete() const { return facts_ && next_ >= facts_->end_offset; }
  bool wait_while_paused();

  HttpTarget target_;
  std::function<Status(const StreamFacts&)> check_header_;
  std::function<void(const Error&, int)> on_retry_;
  std::optional<StreamFacts> facts_;
  std::optional<uint64_t> total_;  // the file's size, once a response said it
  std::vector<uint8_t> prefix_;    // stream bytes before the index could be read
  uint64_t next_ = 0;              // stream offset of the next byte wanted
  bool answered_ = false;          // a response was accepted once: later losses are retried
  std::atomic<bool> range_ignored_{false};
  std::atomic<uint64_t> requests_{0};
  // Why accept() refused bytes: a retry (a record's checksum) or final.
  std::optional<Attempt> refusal_;
  std::unique_ptr<TcpLink> link_;
  uint64_t link_requests_ = 0;  // requests sent on link_
  bool stale_link_ = false;     // link_ was closed by the server while idle
  std::vector<uint8_t> buffer_;
  std::vector<uint8_t> leftover_;  // bytes read past the end of the last response
  std::atomic<bool> stop_{false};
  std::atomic<bool> paused_{false};
  std::atomic<int> reconnects_{0};
  std::mutex pause_mutex_;
  std::condition_variable pause_changed_;
  RateMeter rate_;
};

}  // namespace meshstream::client
