// The HTTP response reader and the range checks of the HTTP stream path
// (client/http_response.h), driven with bytes alone: ranges, plain, chunked
// and until-EOF bodies, a server that ignores Range, truncated and hostile
// responses.
#include "client/http_response.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace meshstream::client {
namespace {

std::span<const uint8_t> bytes_of(const std::string& s) {
  return {reinterpret_cast<const uint8_t*>(s.data()), s.size()};
}

// Feeds `text` in pieces of `piece` bytes; the body collected, or the error.
struct Read {
  Status status;
  std::string body;
  HttpResponseHead head;
  bool done = false;
  std::string leftover;
};
Read read_all(const std::string& text, size_t piece, bool eof = true) {
  Read r;
  HttpResponseReader reader(HttpLimits{}, nullptr, [&](std::span<const uint8_t> b) -> Status {
    r.body.append(reinterpret_cast<const char*>(b.data()), b.size());
    return {};
  });
  for (size_t at = 0; at < text.size() && r.status; at += piece) {
    r.status = reader.feed(bytes_of(text.substr(at, piece)));
  }
  if (r.status && eof && !reader.done()) r.status = reader.end_of_input();
  if (reader.head_done()) r.head = reader.head();
  r.done = reader.done();
  const auto rest = reader.leftover();
  r.leftover.assign(rest.begin(), rest.end());
  return r;
}

TEST(HttpUrl, ParsesHostPortPathAndModel) {
  auto u = parse_http_url("http://127.0.0.1:8080/models/bunny.hcs");
  ASSERT_TRUE(u) << u.error().message;
  EXPECT_EQ(u->host, "127.0.0.1");
  EXPECT_EQ(u->port, 8080);
  EXPECT_EQ(u->target, "/models/bunny.hcs");
  EXPECT_EQ(u->model, "bunny");
  auto v6 = parse_http_url("http://[::1]/a/b.HCS?v=2");
  ASSERT_TRUE(v6) << v6.error().message;
  EXPECT_EQ(v6->host, "::1");
  EXPECT_EQ(v6->port, 80);
  EXPECT_EQ(v6->target, "/a/b.HCS?v=2");
  EXPECT_EQ(v6->model, "b");
  EXPECT_NE(range_request(*v6, 10, 19).find("Host: [::1]\r\n"), std::string::npos);
}

TEST(HttpUrl, RefusesWhatItCannotFetch) {
  for (const std::string bad :
       {"https://h/x.hcs", "http://h", "http:///x.hcs", "http://h:0/x.hcs", "http://h:99999/x.hcs",
        "http://h:x/x.hcs", "http://h/dir/", "http://u@h/x.hcs", "http://h/a b.hcs"}) {
    auto u = parse_http_url(bad);
    ASSERT_FALSE(u) << bad;
    EXPECT_EQ(u.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(u.error().message.find(bad.substr(0, 10)), std::string::npos) << u.error().message;
  }
  EXPECT_NE(parse_http_url("https://h/x.hcs").error().message.find("https is not supported"),
            std::string::npos);
}

TEST(HttpRequest, AsksForAnInclusiveRangeOnAKeptAliveConnection) {
  auto u = parse_http_url("http://example.org:81/m.hcs");
  ASSERT_TRUE(u);
  const std::string r = range_request(*u, 100, 199);
  EXPECT_EQ(r.rfind("GET /m.hcs HTTP/1.1\r\n", 0), 0u);
  EXPECT_NE(r.find("Host: example.org:81\r\n"), std::string::npos);
  EXPECT_NE(r.find("Range: bytes=100-199\r\n"), std::string::npos);
  EXPECT_NE(r.find("Accept-Encoding: identity\r\n"), std::string::npos);
  EXPECT_EQ(r.substr(r.size() - 4), "\r\n\r\n");
  EXPECT_EQ(range_request(*u, 0, std::nullopt).find("Range:"), std::string::npos);
  EXPECT_NE(range_request(*u, 5, std::nullopt).find("Range: bytes=5-\r\n"), std::string::npos);
}

TEST(ContentRange, ParsesTheFormsOfRfc9110) {
  auto r = parse_content_range("bytes 0-99/1000");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->first, 0u);
  EXPECT_EQ(r->last, 99u);
  EXPECT_EQ(r->total, 1000u);
  auto star = parse_content_range("bytes 10-19/*");
  ASSERT_TRUE(star);
  EXPECT_FALSE(star->total);
  auto unsatisfied = parse_content_range("bytes */1000");
  ASSERT_TRUE(unsatisfied);
  EXPECT_TRUE(unsatisfied->unsatisfied);
}

TEST(ContentRange, RefusesMalformedValuesNamingThem) {
  for (const std::string bad :
       {"", "bytes", "items 0-9/10", "bytes 0-9", "bytes 9-0/10", "bytes 0-10/10", "bytes -1-5/10",
        "bytes 0-99999999999999999999/*", "bytes a-b/10", "bytes */*", "bytes 0-9/ten"}) {
    auto r = parse_content_range(bad);
    ASSERT_FALSE(r) << bad;
    EXPECT_EQ(r.error().code, ErrorCode::kParse);
    EXPECT_NE(r.error().message.find("Content-Range"), std::string::npos);
  }
}

const std::string kPartial =
    "HTTP/1.1 206 Partial Content\r\nContent-Type: application/octet-stream\r\n"
    "Content-Range: bytes 100-109/1000\r\nContent-Length: 10\r\n\r\n0123456789";

TEST(HttpResponseReader, ReadsAPlainBodyInAnyPieces) {
  for (size_t piece : {1, 2, 7, 64, 4096}) {
    Read r = read_all(kPartial, piece);
    ASSERT_TRUE(r.status) << piece << ": " << r.status.error().message;
    EXPECT_TRUE(r.done);
    EXPECT_EQ(r.body, "0123456789");
    EXPECT_EQ(r.head.status, 206);
    EXPECT_EQ(r.head.content_length, 10u);
    EXPECT_EQ(r.head.content_range, "bytes 100-109/1000");
    EXPECT_TRUE(r.head.keep_alive);
  }
}

TEST(HttpResponseReader, ReadsAChunkedBody) {
  const std::string chunked =
      "HTTP/1.1 200 OK\r\nTransfer-Encoding: chunked\r\n\r\n"
      "4\r\nMHCS\r\n3;ext=1\r\nabc\r\n0\r\nTrailer: x\r\n\r\n";
  for (size_t piece : {1, 3, 1000}) {
    Read r = read_all(chunked, piece);
    ASSERT_TRUE(r.status) << r.status.error().message;
    EXPECT_TRUE(r.done);
    EXPECT_TRUE(r.head.chunked);
    EXPECT_FALSE(r.head.content_length);
    EXPECT_EQ(r.body, "MHCSabc");
  }
}

TEST(HttpResponseReader, ReadsABodyThatRunsUntilTheConnectionCloses) {
  Read r = read_all("HTTP/1.0 200 OK\r\nContent-Type: application/octet-stream\r\n\r\nabcdef", 4);
  ASSERT_TRUE(r.status) << r.status.error().message;
  EXPECT_TRUE(r.done);
  EXPECT_FALSE(r.head.keep_alive);
  EXPECT_EQ(r.body, "abcdef");
}

TEST(HttpResponseReader, KeepsTheNextResponsesBytes) {
  Read r = read_all(kPartial + "HTTP/1.1 206", 5, false);
  ASSERT_TRUE(r.status);
  EXPECT_TRUE(r.done);
  EXPECT_EQ(r.body, "0123456789");
  EXPECT_EQ(r.leftover, "HTTP/1.1 206");
}

TEST(HttpResponseReader, ATruncatedResponseSaysWhatWasMissing) {
  Read head_cut = read_all(kPartial.substr(0, 30), 8);
  ASSERT_FALSE(head_cut.status);
  EXPECT_EQ(head_cut.status.error().code, ErrorCode::kTruncated);
  EXPECT_NE(head_cut.status.error().message.find("before the response header"), std::string::npos);
  Read body_cut = read_all(kPartial.substr(0, kPartial.size() - 3), 8);
  ASSERT_FALSE(body_cut.status);
  EXPECT_EQ(body_cut.status.error().code, ErrorCode::kTruncated);
  EXPECT_NE(body_cut.status.error().message.find("after 7 of 10 body bytes"), std::string::npos)
      << body_cut.status.error().message;
  Read chunk_cut = read_all("HTTP/1.1 200 OK\r\nTransfer-Encoding: chunked\r\n\r\n4\r\nMH", 8);
  ASSERT_FALSE(chunk_cut.status);
  EXPECT_NE(chunk_cut.status.error().message.find("chunked"), std::string::npos);
}

TEST(HttpResponseReader, RefusesAHugeHeader) {
  std::string huge = "HTTP/1.1 200 OK\r\n";
  for (int i = 0; i < 2000; ++i) huge += "X-Padding-" + std::to_string(i) + ": 0123456789\r\n";
  Read r = read_all(huge + "\r\n", 512, false);
  ASSERT_FALSE(r.status);
  EXPECT_EQ(r.status.error().code, ErrorCode::kLimit);
  EXPECT_NE(r.status.error().message.find("header"), std::string::npos);
}

TEST(HttpResponseReader, RefusesAnEndlessChunkHeader) {
  Read r =
      read_all("HTTP/1.1 200 OK\r\nTransfer-Encoding: chunked\r\n\r\n4;" + std::string(100000, 'x'),
               1000, false);
  ASSERT_FALSE(r.status);
}

TEST(HttpResponseReader, RefusesGarbageAndBadLengths) {
  for (const std::string bad : {"SSH-2.0-OpenSSH_9.2\r\n\r\n", "HTTP/1.1 abc OK\r\n\r\n",
                                "HTTP/1.1 200 OK\r\nContent-Length: 12abc\r\n\r\n",
                                "HTTP/1.1 200 OK\r\nContent-Length: 5\r\nContent-Length: 6\r\n\r\n",
                                "HTTP/1.1 200 OK\r\nTransfer-Encoding: chunked\r\n\r\nzz\r\n"}) {
    Read r = read_all(bad, 3, false);
    ASSERT_FALSE(r.status) << bad;
    EXPECT_EQ(r.status.error().code, ErrorCode::kParse) << bad;
  }
}

TEST(HttpResponseReader, TheHeadIsCheckedBeforeAnyBodyByte) {
  std::string body;
  HttpResponseReader reader(
      HttpLimits{},
      [](const HttpResponseHead& h) -> Status {
        if (h.status == 206) return make_error(ErrorCode::kUnsupported, "no thanks");
        return {};
      },
      [&](std::span<const uint8_t> b) -> Status {
        body.append(reinterpret_cast<const char*>(b.data()), b.size());
        return {};
      });
  Status s = reader.feed(bytes_of(kPartial));
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().message, "no thanks");
  EXPECT_TRUE(body.empty());
  EXPECT_FALSE(reader.feed(bytes_of("more")));  // spent: repeats the error
}

HttpResponseHead head(int status, std::string range, std::optional<uint64_t> length,
                      std::string type = "application/octet-stream") {
  HttpResponseHead h;
  h.status = status;
  h.reason = "R";
  h.content_range = std::move(range);
  h.content_length = length;
  h.content_type = std::move(type);
  return h;
}

const std::string kUrl = "http://h/m.hcs";

TEST(CheckResponse, APartialAnswerMapsToStreamOffsets) {
  auto p = check_response(head(206, "bytes 100-199/1000", 100), kUrl, 100, 199, std::nullopt);
  ASSERT_TRUE(p) << p.error().message;
  EXPECT_FALSE(p->whole);
  EXPECT_EQ(p->stream_offset, 100u);
  EXPECT_EQ(p->length, 100u);
  EXPECT_EQ(p->total, 1000u);
  // A range cut at the file's end is fine (the probe of a small file).
  auto end = check_response(head(206, "bytes 0-49/50", 50), kUrl, 0, 65535, std::nullopt);
  ASSERT_TRUE(end) << end.error().message;
  EXPECT_EQ(end->length, 50u);
}

TEST(CheckResponse, AServerThatIgnoresRangeSendsTheWholeFile) {
  auto p = check_response(head(200, "", 1000), kUrl, 500, 599, std::nullopt);
  ASSERT_TRUE(p) << p.error().message;
  EXPECT_TRUE(p->whole);
  EXPECT_EQ(p->stream_offset, 0u);
  EXPECT_EQ(p->total, 1000u);
  auto chunked = check_response(head(200, "", std::nullopt), kUrl, 0, 99, std::nullopt);
  ASSERT_TRUE(chunked);
  EXPECT_FALSE(chunked->length);
}

TEST(CheckResponse, RefusesWrongRangesAndLengths) {
  struct Case {
    HttpResponseHead h;
    uint64_t first;
    std::optional<uint64_t> last;
    std::optional<uint64_t> total;
    std::string says;
  };
  const std::vector<Case> cases = {
      {head(206, "", 10), 0, 9, {}, "without a Content-Range"},
      {head(206, "bytes 5-14/100", 10), 0, 9, {}, "asked for bytes 0-9, the server sent 5-14"},
      {head(206, "bytes 0-19/100", 20), 0, 9, {}, "the server sent 0-19"},
      {head(206, "bytes 0-9/100", 11), 0, 9, {}, "Content-Length 11 disagrees"},
      {head(206, "bytes 0-9/100", 10), 0, 9, 200, "the file changed on the server"},
      {head(200, "", 300), 0, 9, 200, "the file changed on the server"},
      {head(206, "bytes 0-4/100", 5), 0, 9, {}, "up to 4 of 100"},
      {head(206, "bytes x", 5), 0, 9, {}, "Content-Range 'bytes x'"},
      {head(206, "bytes */100", 0), 0, 9, {}, "unsatisfied"},
  };
  for (const Case& c : cases) {
    auto p = check_response(c.h, kUrl, c.first, c.last, c.total);
    ASSERT_FALSE(p) << c.says;
    EXPECT_EQ(p.error().message.rfind(kUrl + ": ", 0), 0u) << p.error().message;
    EXPECT_NE(p.error().message.find(c.says), std::string::npos) << p.error().message;
  }
}

TEST(CheckResponse, StatusesAndPagesThatAreNotStreams) {
  auto missing = check_response(head(404, "", 10), kUrl, 0, 9, std::nullopt);
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code, ErrorCode::kUnsupported);
  EXPECT_NE(missing.error().message.find("HTTP 404"), std::string::npos);
  HttpResponseHead moved = head(301, "", 0);
  moved.location = "http://other/m.hcs";
  auto redirect = check_response(moved, kUrl, 0, 9, std::nullopt);
  ASSERT_FALSE(redirect);
  EXPECT_NE(redirect.error().message.find("redirects to http://other/m.hcs"), std::string::npos);
  auto busy = check_response(head(503, "", 0), kUrl, 0, 9, std::nullopt);
  ASSERT_FALSE(busy);
  EXPECT_EQ(busy.error().code, ErrorCode::kIo);  // worth retrying
  auto html = check_response(head(200, "", 100, "text/html; charset=utf-8"), kUrl, 0, 9, {});
  ASSERT_FALSE(html);
  EXPECT_NE(html.error().message.find("HTML page"), std::string::npos);
  auto outside = check_response(head(416, "bytes */10", 0), kUrl, 50, 59, std::nullopt);
  ASSERT_FALSE(outside);
  EXPECT_NE(outside.error().message.find("outside the file"), std::string::npos);
}

}  // namespace
}  // namespace meshstream::client
