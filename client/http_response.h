// The HTTP side of `meshstream-client http://HOST[:PORT]/PATH/MODEL.hcs`,
// without sockets: the URL, the request text, and an incremental reader of
// one HTTP/1.1 response (Boost.Beast's parser underneath: status line,
// fields, plain, chunked and until-EOF bodies) that hands the body on as
// it arrives; then the check of a response against the range that was
// asked for. Pure functions and plain data, so the unit tests and the fuzz
// target (tests/fuzz/fuzz_http_response.cpp) drive them with bytes alone.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "common/base/result.h"

namespace meshstream::client {

// http://HOST[:PORT]/PATH (IPv6 as [::1]). `model` is the file name
// without ".hcs", what the events call the model.
struct HttpUrl {
  std::string host;
  uint16_t port = 80;
  std::string target;  // "/PATH/MODEL.hcs" (with any query), as sent
  std::string model;
  std::string text;  // the URL as given, for messages
};
bool looks_like_http_url(std::string_view text);  // starts with http:// or https://
// kInvalidArgument naming the URL and the problem (https, no host, a bad
// port, no path to a file).
Result<HttpUrl> parse_http_url(const std::string& text);

// GET `target` for stream bytes [first, last] (inclusive; no Range header
// when `last` is nullopt and first is 0), keep-alive.
std::string range_request(const HttpUrl& url, uint64_t first, std::optional<uint64_t> last);

// "bytes FIRST-LAST/TOTAL" (TOTAL may be "*"), as RFC 9110 writes it.
struct ContentRange {
  uint64_t first = 0;
  uint64_t last = 0;              // inclusive
  std::optional<uint64_t> total;  // nullopt for "*"
  bool unsatisfied = false;       // "bytes */TOTAL" (a 416's form)
};
// kParse naming the value and what is wrong with it.
Result<ContentRange> parse_content_range(std::string_view value);

// What a response's header said.
struct HttpResponseHead {
  int status = 0;
  std::string reason;
  int version = 11;
  std::optional<uint64_t> content_length;
  bool chunked = false;
  std::string content_type;
  std::string content_range;  // the raw value ("" when absent)
  std::string location;
  bool keep_alive = true;
};

struct HttpLimits {
  uint32_t max_header_bytes = 16 * 1024;  // status line and fields together
};

// One response, fed the bytes read from the connection in any pieces.
class HttpResponseReader {
 public:
  // Called once, when the header is complete, before any body byte; an
  // error stops the reader with it (e.g. a status that is not wanted).
  using HeadCheck = std::function<Status(const HttpResponseHead&)>;
  // Body bytes, in order, as they are parsed (a chunked body's chunks
  // without their framing). Returning an error stops the reader with it.
  using BodySink = std::function<Status(std::span<const uint8_t>)>;
  HttpResponseReader(HttpLimits limits, HeadCheck on_head, BodySink sink);
  ~HttpResponseReader();
  HttpResponseReader(const HttpResponseReader&) = delete;
  HttpResponseReader& operator=(const HttpResponseReader&) = delete;

  // Parses what it can of `bytes` (keeping an incomplete line for the next
  // feed). Bytes after the end of the message are kept as leftover() (the
  // next response's). kParse for a malformed response, kLimit for a header
  // (or a chunk header) over the limit, or the callbacks' error; after an
  // error the reader is spent and repeats it.
  Status feed(std::span<const uint8_t> bytes);
  // The connection closed: fine for a body that runs until EOF, kTruncated
  // (naming what was missing) otherwise.
  Status end_of_input();

  bool head_done() const;
  const HttpResponseHead& head() const;       // valid once head_done()
  bool done() const;                          // the whole message was read
  uint64_t body_bytes() const;                // body bytes handed to the sink so far
  std::span<const uint8_t> leftover() const;  // bytes after the message (once done())

 private:
  class Parser;
  std::unique_ptr<Parser> parser_;
};

// How to read a response's body as stream bytes, once its head is known.
struct BodyPlan {
  uint64_t stream_offset = 0;      // stream offset of the body's first byte
  std::optional<uint64_t> length;  // body bytes to expect (nullopt: until the end)
  std::optional<uint64_t> total;   // the whole stream's size, when the response says it
  bool whole = false;              // a 200: the server ignored the Range header
};

// Checks `head` of the answer to a request for [first, last] (`last`
// nullopt: to the end) against what a static file server must send: 206
// with a Content-Range that starts at `first`, ends at or before `last`,
// agrees with Content-Length and with `known_total` (the size seen before);
// or 200 (Range ignored) with the whole file. Errors name `url` and the
// problem: kIo for statuses worth retrying (408, 429, 5xx), kParse for a
// bad Content-Range or lengths that disagree, kUnsupported for any other
// status (404, a redirect with its Location, ...), kParse for a body
// declared as an HTML page.
Result<BodyPlan> check_response(const HttpResponseHead& head, const std::string& url,
                                uint64_t first, std::optional<uint64_t> last,
                                std::optional<uint64_t> known_total);

}  // namespace meshstream::client
