#include "client/http_response.h"

#include <algorithm>
#include <boost/beast/http/basic_parser.hpp>
#include <boost/beast/http/error.hpp>
#include <cctype>
#include <charconv>
#include <limits>
#include <vector>

namespace meshstream::client {

namespace http = boost::beast::http;
using boost::beast::error_code;

namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

// A whole decimal number with no sign, spaces or overflow.
std::optional<uint64_t> whole_number(std::string_view s) {
  if (s.empty() || s.size() > 19) return std::nullopt;
  uint64_t value = 0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return value;
}

// Printable, and short enough for a message.
std::string printable(std::string_view s) {
  std::string out;
  for (char c : s.substr(0, 80)) out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  if (s.size() > 80) out += "...";
  return out;
}
std::string quoted(std::string_view s) { return "'" + printable(s) + "'"; }

}  // namespace

bool looks_like_http_url(std::string_view text) {
  const std::string l = lower(text.substr(0, 8));
  return l.rfind("http://", 0) == 0 || l.rfind("https://", 0) == 0;
}

Result<HttpUrl> parse_http_url(const std::string& text) {
  auto bad = [&](const std::string& why) {
    return make_error(ErrorCode::kInvalidArgument, "URL " + quoted(text) + ": " + why);
  };
  const std::string l = lower(text.substr(0, 8));
  if (l.rfind("https://", 0) == 0)
    return bad("https is not supported (no TLS in this client): use http://");
  if (l.rfind("http://", 0) != 0) return bad("not an http:// URL");
  HttpUrl url;
  url.text = text;
  const std::string rest = text.substr(7);
  const size_t slash = rest.find('/');
  const std::string authority = rest.substr(0, slash);
  if (authority.find('@') != std::string::npos) return bad("user names in URLs are not supported");
  if (slash == std::string::npos) return bad("no path to an .hcs file after the host");
  url.target = rest.substr(slash);
  if (url.target.find_first_of(" \r\n\t") != std::string::npos)
    return bad("the path holds spaces or control characters (percent-encode them)");
  std::string host = authority, port;
  if (!host.empty() && host.front() == '[') {
    const size_t close = host.find(']');
    if (close == std::string::npos) return bad("an IPv6 host needs its closing ']'");
    port = host.substr(close + 1);
    host = host.substr(1, close - 1);
    if (!port.empty() && port.front() != ':') return bad("unexpected text after the IPv6 host");
    if (!port.empty()) port = port.substr(1);
  } else if (const size_t colon = host.rfind(':'); colon != std::string::npos) {
    port = host.substr(colon + 1);
    host = host.substr(0, colon);
  }
  if (host.empty()) return bad("no host");
  url.host = host;
  if (!port.empty() || authority.back() == ':') {
    auto value = whole_number(port);
    if (!value || *value == 0 || *value > 65535)
      return bad("port " + quoted(port) + " is not a port (1 to 65535)");
    url.port = static_cast<uint16_t>(*value);
  }
  // The model: the file name without query, fragment and ".hcs".
  std::string path = url.target.substr(0, url.target.find_first_of("?#"));
  const size_t fragment = url.target.find('#');
  if (fragment != std::string::npos) url.target = url.target.substr(0, fragment);
  const std::string file = path.substr(path.rfind('/') + 1);
  if (file.empty()) return bad("the path names a folder, not an .hcs file");
  url.model = file;
  if (lower(file).size() > 4 && lower(file).substr(file.size() - 4) == ".hcs")
    url.model = file.substr(0, file.size() - 4);
  return url;
}

std::string range_request(const HttpUrl& url, uint64_t first, std::optional<uint64_t> last) {
  std::string host = url.host.find(':') != std::string::npos ? "[" + url.host + "]" : url.host;
  if (url.port != 80) host += ":" + std::to_string(url.port);
  std::string r = "GET " + url.target + " HTTP/1.1\r\nHost: " + host +
                  "\r\nUser-Agent: meshstream-client\r\nAccept: */*\r\n"
                  "Accept-Encoding: identity\r\nConnection: keep-alive\r\n";
  if (last || first > 0) {
    r += "Range: bytes=" + std::to_string(first) + "-" + (last ? std::to_string(*last) : "") +
         "\r\n";
  }
  return r + "\r\n";
}

Result<ContentRange> parse_content_range(std::string_view value) {
  auto bad = [&](const std::string& why) {
    return make_error(ErrorCode::kParse, "Content-Range " + quoted(value) + " " + why);
  };
  std::string_view v = value;
  while (!v.empty() && (v.front() == ' ' || v.front() == '\t')) v.remove_prefix(1);
  while (!v.empty() && (v.back() == ' ' || v.back() == '\t')) v.remove_suffix(1);
  if (lower(v.substr(0, 6)) != "bytes ") return bad("is not in bytes (\"bytes FIRST-LAST/TOTAL\")");
  v.remove_prefix(6);
  const size_t slash = v.find('/');
  if (slash == std::string_view::npos) return bad("has no '/TOTAL'");
  const std::string_view range = v.substr(0, slash), total = v.substr(slash + 1);
  ContentRange r;
  if (total != "*") {
    r.total = whole_number(total);
    if (!r.total) return bad("has a total that is not a number");
  }
  if (range == "*") {
    if (!r.total) return bad("has neither a range nor a total");
    r.unsatisfied = true;
    return r;
  }
  const size_t dash = range.find('-');
  if (dash == std::string_view::npos) return bad("has no FIRST-LAST");
  auto first = whole_number(range.substr(0, dash)), last = whole_number(range.substr(dash + 1));
  if (!first || !last) return bad("has a FIRST-LAST that is not two numbers");
  if (*last < *first) return bad("ends before it starts");
  if (r.total && *last >= *r.total) return bad("ends past the total");
  r.first = *first;
  r.last = *last;
  return r;
}

// Beast's parser with callbacks that fill the head and pass the body on.
class HttpResponseReader::Parser : public http::basic_parser<false> {
 public:
  Parser(HttpLimits limits, HeadCheck on_head, BodySink sink)
      : limits_(limits), on_head_(std::move(on_head)), sink_(std::move(sink)) {
    header_limit(limits.max_header_bytes);
    // Not boost::none: Boost 1.74 compares lengths with the optional, and
    // every length is larger than none. The lengths are checked against
    // the range asked for instead (check_response, the body sink).
    body_limit(std::numeric_limits<std::uint64_t>::max());
    eager(true);
  }
  HttpLimits limits_;
  std::vector<uint8_t> pending;  // bytes not parsed yet (an incomplete line)
  HttpResponseHead head;
  bool head_done = false;
  uint64_t body_bytes = 0;
  std::optional<Error> error;  // the sink's or ours, which Beast only sees as a code

 private:
  void on_request_impl(http::verb, boost::beast::string_view, boost::beast::string_view, int,
                       error_code& ec) override {
    ec = http::error::bad_method;  // never called for a response parser
  }
  void on_response_impl(int code, boost::beast::string_view reason, int version,
                        error_code&) override {
    head.status = code;
    head.reason = std::string(reason.substr(0, 120));
    head.version = version;
  }
  void on_field_impl(http::field name, boost::beast::string_view, boost::beast::string_view value,
                     error_code&) override {
    const std::string_view v(value.data(), value.size());
    switch (name) {
      case http::field::content_type:
        head.content_type = std::string(v.substr(0, 200));
        break;
      case http::field::content_range:
        head.content_range = std::string(v.substr(0, 200));
        break;
      case http::field::location:
        head.location = std::string(v.substr(0, 300));
        break;
      default:
        break;
    }
  }
  void on_header_impl(error_code& ec) override {
    head.chunked = chunked();
    head.keep_alive = keep_alive();
    if (content_length()) head.content_length = *content_length();
    head_done = true;
    if (on_head_) {
      if (Status s = on_head_(head); !s) {
        error = s.error();
        ec = http::error::bad_target;  // any code stops Beast; `error` says what happened
      }
    }
  }
  void on_body_init_impl(const boost::optional<std::uint64_t>&, error_code&) override {}
  size_t on_body_impl(boost::beast::string_view body, error_code& ec) override {
    return pass(body, ec);
  }
  void on_chunk_header_impl(std::uint64_t, boost::beast::string_view, error_code&) override {}
  size_t on_chunk_body_impl(std::uint64_t, boost::beast::string_view body,
                            error_code& ec) override {
    return pass(body, ec);
  }
  void on_finish_impl(error_code&) override {}

  size_t pass(boost::beast::string_view body, error_code& ec) {
    body_bytes += body.size();
    if (sink_) {
      Status s = sink_(
          std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(body.data()), body.size()));
      if (!s) {
        error = s.error();
        ec = http::error::bad_target;  // any code stops Beast; `error` says what happened
        return 0;
      }
    }
    return body.size();
  }

  HeadCheck on_head_;
  BodySink sink_;
};

HttpResponseReader::HttpResponseReader(HttpLimits limits, HeadCheck on_head, BodySink sink)
    : parser_(std::make_unique<Parser>(limits, std::move(on_head), std::move(sink))) {}
HttpResponseReader::~HttpResponseReader() = default;

namespace {

Error beast_error(const error_code& ec) {
  if (ec == http::error::header_limit)
    return Error{ErrorCode::kLimit, "the response header is larger than this client accepts"};
  if (ec == http::error::buffer_overflow || ec == http::error::body_limit)
    return Error{ErrorCode::kLimit, "the response is larger than this client accepts"};
  return Error{ErrorCode::kParse, "malformed HTTP response (" + ec.message() + ")"};
}

}  // namespace

Status HttpResponseReader::feed(std::span<const uint8_t> bytes) {
  Parser& p = *parser_;
  if (p.error) return tl::unexpected(*p.error);
  std::vector<uint8_t>& in = p.pending;
  in.insert(in.end(), bytes.begin(), bytes.end());
  size_t used = 0;
  while (used < in.size() && !p.is_done()) {
    error_code ec;
    const size_t n = p.put(boost::asio::const_buffer(in.data() + used, in.size() - used), ec);
    used += n;
    if (ec == http::error::need_more) break;
    if (ec) {
      if (!p.error) p.error = beast_error(ec);
      return tl::unexpected(*p.error);
    }
    if (n == 0) break;
  }
  in.erase(in.begin(), in.begin() + static_cast<std::ptrdiff_t>(used));
  // Beast bounds the header; an endless chunk header line is ours to bound.
  if (!p.is_done() && p.head_done && in.size() > p.limits_.max_header_bytes) {
    p.error = Error{ErrorCode::kLimit, "a chunk header is longer than this client accepts"};
    return tl::unexpected(*p.error);
  }
  return {};
}

Status HttpResponseReader::end_of_input() {
  Parser& p = *parser_;
  if (p.error) return tl::unexpected(*p.error);
  if (p.is_done()) return {};
  if (!p.head_done) {
    return make_error(ErrorCode::kTruncated, "the connection closed before the response header");
  }
  error_code ec;
  p.put_eof(ec);
  if (!ec && p.is_done()) return {};
  std::string missing = p.head.chunked ? "before the chunked body's last chunk"
                        : p.head.content_length
                            ? "after " + std::to_string(p.body_bytes) + " of " +
                                  std::to_string(*p.head.content_length) + " body bytes"
                            : "before the body ended";
  return make_error(ErrorCode::kTruncated, "the connection closed " + missing);
}

bool HttpResponseReader::head_done() const { return parser_->head_done; }
const HttpResponseHead& HttpResponseReader::head() const { return parser_->head; }
bool HttpResponseReader::done() const { return parser_->is_done(); }
uint64_t HttpResponseReader::body_bytes() const { return parser_->body_bytes; }
std::span<const uint8_t> HttpResponseReader::leftover() const {
  if (!parser_->is_done()) return {};
  return parser_->pending;
}

Result<BodyPlan> check_response(const HttpResponseHead& head, const std::string& url,
                                uint64_t first, std::optional<uint64_t> last,
                                std::optional<uint64_t> known_total) {
  const std::string status = "HTTP " + std::to_string(head.status) +
                             (head.reason.empty() ? "" : " " + printable(head.reason));
  auto fail = [&](ErrorCode code, const std::string& why) {
    return make_error(code, url + ": " + why);
  };
  if (head.status == 408 || head.status == 429 || (head.status >= 500 && head.status <= 599))
    return fail(ErrorCode::kIo, "the server answered " + status);
  if (head.status != 200 && head.status != 206) {
    std::string why = "the server answered " + status;
    if (head.status == 404 || head.status == 410) why += ": no such file";
    if (head.status >= 300 && head.status < 400 && !head.location.empty())
      why += ": it redirects to " + head.location + " (use that URL)";
    if (head.status == 416) why += ": the range asked for is outside the file";
    return fail(ErrorCode::kUnsupported, why);
  }
  if (lower(head.content_type).find("text/html") != std::string::npos) {
    return fail(ErrorCode::kParse, "the server sent an HTML page (" + quoted(head.content_type) +
                                       "), not an .hcs stream");
  }
  BodyPlan plan;
  if (head.status == 200) {
    // Range ignored (or none asked for): the whole file from byte 0.
    plan.whole = true;
    plan.length = head.content_length;
    plan.total = head.content_length;
    if (known_total && plan.total && *plan.total != *known_total) {
      return fail(ErrorCode::kCorrupt, "the file changed on the server: it had " +
                                           std::to_string(*known_total) + " bytes, now " +
                                           std::to_string(*plan.total));
    }
    return plan;
  }
  if (head.content_range.empty())
    return fail(ErrorCode::kParse, "a 206 (partial content) answer without a Content-Range");
  auto range = parse_content_range(head.content_range);
  if (!range) return fail(ErrorCode::kParse, range.error().message);
  if (range->unsatisfied) return fail(ErrorCode::kParse, "a 206 answer with an unsatisfied range");
  if (range->first != first || (last && range->last > *last)) {
    return fail(ErrorCode::kParse, "asked for bytes " + std::to_string(first) + "-" +
                                       (last ? std::to_string(*last) : "") + ", the server sent " +
                                       std::to_string(range->first) + "-" +
                                       std::to_string(range->last));
  }
  const uint64_t length = range->last - range->first + 1;
  if (head.content_length && *head.content_length != length) {
    return fail(ErrorCode::kParse, "Content-Length " + std::to_string(*head.content_length) +
                                       " disagrees with Content-Range " + head.content_range);
  }
  if (known_total && range->total && *range->total != *known_total) {
    return fail(ErrorCode::kCorrupt, "the file changed on the server: it had " +
                                         std::to_string(*known_total) + " bytes, now " +
                                         std::to_string(*range->total));
  }
  // A range that stops short of what was asked without reaching the end.
  if (last && range->last < *last && range->total && range->last + 1 != *range->total) {
    return fail(ErrorCode::kParse, "asked for bytes up to " + std::to_string(*last) +
                                       ", the server sent up to " + std::to_string(range->last) +
                                       " of " + std::to_string(*range->total));
  }
  plan.stream_offset = first;
  plan.length = length;
  plan.total = range->total;
  return plan;
}

}  // namespace meshstream::client
