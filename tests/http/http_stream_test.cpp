// The HTTP stream path (client/http_stream_client.h) in-process against a
// scripted web server on a real loopback socket: each test decides what the
// server answers (correct ranges, dropped connections, altered bytes, a
// server that ignores Range, chunked bodies, hostile and stalled answers),
// and checks the final mesh against decode_hcs of the same bytes, or the
// error, and that nothing loops or hangs.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <functional>
#include <mutex>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "client/decoded_stream.h"
#include "client/http_stream_client.h"
#include "common/codec/container.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/procedural.h"

namespace meshstream::client {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// The first request's size here: the demo model's stream is smaller than
// the default 64 KiB, and these tests want many requests.
constexpr uint64_t kProbe = 2048;

// What the script answers one request with.
struct Reply {
  std::string bytes;
  size_t cut_after = std::string::npos;  // close the connection after this many bytes
  bool stall = false;                    // send `bytes`, then nothing, keep the socket open
  bool close = false;                    // close after sending
};

struct Request {
  std::string text;
  std::optional<uint64_t> first, last;  // its Range, if any
};

// One listening socket; one thread serving connection after connection,
// request after request, by the script.
class ScriptedServer {
 public:
  using Script = std::function<Reply(const Request&, int number)>;
  explicit ScriptedServer(Script script) : script_(std::move(script)) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    int one = 1;
    ::setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
    ::listen(fd_, 16);
    socklen_t len = sizeof a;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] { serve(); });
  }
  ~ScriptedServer() {
    stop_ = true;
    thread_.join();
    ::close(fd_);
  }
  uint16_t port() const { return port_; }
  std::vector<Request> requests() const {
    std::lock_guard lock(mutex_);
    return requests_;
  }
  int connections() const { return connections_; }

 private:
  bool readable(int fd, int ms) {
    pollfd p{fd, POLLIN, 0};
    return ::poll(&p, 1, ms) > 0;
  }
  void serve() {
    while (!stop_) {
      if (!readable(fd_, 20)) continue;
      const int c = ::accept(fd_, nullptr, nullptr);
      if (c < 0) continue;
      ++connections_;
      converse(c);
      ::close(c);
    }
  }
  void converse(int c) {
    std::string in;
    while (!stop_) {
      const size_t end = in.find("\r\n\r\n");
      if (end == std::string::npos) {
        if (!readable(c, 20)) continue;
        char buf[4096];
        const ssize_t n = ::recv(c, buf, sizeof buf, 0);
        if (n <= 0) return;
        in.append(buf, static_cast<size_t>(n));
        continue;
      }
      Request r;
      r.text = in.substr(0, end + 4);
      in.erase(0, end + 4);
      std::smatch m;
      static const std::regex range(R"(Range: bytes=(\d+)-(\d*)\r\n)");
      if (std::regex_search(r.text, m, range)) {
        r.first = std::stoull(m[1]);
        if (m[2].length()) r.last = std::stoull(m[2]);
      }
      int number;
      {
        std::lock_guard lock(mutex_);
        requests_.push_back(r);
        number = static_cast<int>(requests_.size());
      }
      const Reply reply = script_(r, number);
      const size_t n = std::min(reply.cut_after, reply.bytes.size());
      if (!send_all(c, reply.bytes.substr(0, n))) return;
      if (reply.cut_after != std::string::npos || reply.close) return;
      if (reply.stall) {
        while (!stop_ && !readable(c, 20)) {
        }
        return;
      }
    }
  }
  static bool send_all(int c, const std::string& s) {
    size_t at = 0;
    while (at < s.size()) {
      const ssize_t n = ::send(c, s.data() + at, s.size() - at, MSG_NOSIGNAL);
      if (n <= 0) return false;
      at += static_cast<size_t>(n);
    }
    return true;
  }

  Script script_;
  int fd_ = -1;
  uint16_t port_ = 0;
  std::atomic<bool> stop_{false};
  std::atomic<int> connections_{0};
  mutable std::mutex mutex_;
  std::vector<Request> requests_;
  std::thread thread_;
};

// A correct answer from a static file server.
std::string partial(const std::string& file, const Request& r) {
  const uint64_t first = r.first.value_or(0);
  const uint64_t last = std::min<uint64_t>(r.last.value_or(file.size() - 1), file.size() - 1);
  return "HTTP/1.1 206 Partial Content\r\nContent-Type: application/octet-stream\r\n"
         "Content-Range: bytes " +
         std::to_string(first) + "-" + std::to_string(last) + "/" + std::to_string(file.size()) +
         "\r\nContent-Length: " + std::to_string(last - first + 1) + "\r\n\r\n" +
         file.substr(first, last - first + 1);
}
std::string whole(const std::string& file) {
  return "HTTP/1.1 200 OK\r\nContent-Type: application/octet-stream\r\nContent-Length: " +
         std::to_string(file.size()) + "\r\n\r\n" + file;
}
std::string chunked_whole(const std::string& file, size_t piece) {
  std::string out = "HTTP/1.1 200 OK\r\nTransfer-Encoding: chunked\r\n\r\n";
  for (size_t at = 0; at < file.size(); at += piece) {
    const std::string c = file.substr(at, piece);
    char size[32];
    std::snprintf(size, sizeof size, "%zx\r\n", c.size());
    out += size + c + "\r\n";
  }
  return out + "0\r\n\r\n";
}

struct Outcome {
  StreamOutcome outcome;
  Mesh mesh;
  int reconnects = 0;
  uint64_t requests = 0;
  bool range_ignored = false;
  double seconds = 0;
  std::optional<StreamFacts> facts;
};

class HttpStreamTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    EncodeOptions options;
    options.asa_guidance = false;  // these tests stream bytes; ASA is not what they check
    auto stream = encode_hcs(make_demo_mesh(20000), options);
    ASSERT_TRUE(stream);
    file_ = new std::string(stream->begin(), stream->end());
    auto expected = decode_hcs(*stream);
    ASSERT_TRUE(expected);
    expected_ = new Mesh(std::move(*expected));
  }
  static void TearDownTestSuite() {
    delete file_;
    delete expected_;
  }

  static Outcome stream(const ScriptedServer& server, uint64_t range_bytes = 4096,
                        ReconnectPolicy policy = fast_policy(), Budget budget = Budget::all()) {
    HttpTarget t;
    auto url = parse_http_url("http://127.0.0.1:" + std::to_string(server.port()) + "/m/demo.hcs");
    EXPECT_TRUE(url);
    t.url = *url;
    t.range_bytes = range_bytes;
    t.probe_bytes = kProbe;
    t.reconnect = policy;
    t.budget = budget;
    HttpStreamClient client(t);
    DecodedStream decoded;
    Outcome o;
    const auto start = Clock::now();
    client.run(decoded, [&](const StreamFacts& f) { o.facts = f; });
    o.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    o.outcome = *decoded.outcome();
    MeshChanges changes;
    decoded.take(o.mesh, changes);
    o.reconnects = client.reconnects();
    o.requests = client.requests();
    o.range_ignored = client.range_ignored();
    return o;
  }
  static ReconnectPolicy fast_policy() {
    ReconnectPolicy p;
    p.first_delay = 5ms;
    p.max_delay = 20ms;
    p.max_attempts = 3;
    p.connect_timeout = 2000ms;
    p.read_timeout = 2000ms;
    return p;
  }
  static void expect_identical(const Outcome& o) {
    ASSERT_TRUE(o.outcome.ok) << o.outcome.error.message;
    EXPECT_EQ(o.outcome.reason, "complete");
    EXPECT_EQ(o.mesh.triangles, expected_->triangles);
    ASSERT_EQ(o.mesh.positions.size(), expected_->positions.size());
    EXPECT_EQ(0, std::memcmp(o.mesh.positions.data(), expected_->positions.data(),
                             o.mesh.positions.size() * sizeof(Vec3f)));
  }
  static std::string error_of(const Outcome& o) {
    EXPECT_FALSE(o.outcome.ok);
    return o.outcome.error.message;
  }

  static std::string* file_;
  static Mesh* expected_;
};
std::string* HttpStreamTest::file_ = nullptr;
Mesh* HttpStreamTest::expected_ = nullptr;

TEST_F(HttpStreamTest, RangesOfWholeRecordsOnOneConnection) {
  ScriptedServer server([](const Request& r, int) { return Reply{partial(*file_, r)}; });
  Outcome o = stream(server, 4096);
  expect_identical(o);
  ASSERT_TRUE(o.facts);
  EXPECT_EQ(server.connections(), 1);
  const auto requests = server.requests();
  ASSERT_GT(requests.size(), 3u);
  EXPECT_EQ(requests[0].first, 0u);
  EXPECT_EQ(requests[0].last, kProbe - 1);
  // Every later request starts where the one before ended and ends on a
  // record boundary, with at least 4096 bytes unless it is the last.
  const auto& ends = o.facts->record_end;
  for (size_t i = 1; i < requests.size(); ++i) {
    ASSERT_TRUE(requests[i].first && requests[i].last);
    const uint64_t end = *requests[i].last + 1;
    EXPECT_NE(std::find(ends.begin(), ends.end(), end), ends.end()) << "request " << i;
    if (i + 1 < requests.size()) {
      EXPECT_EQ(*requests[i + 1].first, end);
      EXPECT_GE(end - *requests[i].first, 4096u);
    }
  }
  EXPECT_EQ(*requests.back().last + 1, file_->size());
}

TEST_F(HttpStreamTest, ADroppedConnectionResumesFromTheLastGoodRecord) {
  uint64_t cut_at = 0;
  ScriptedServer server([&](const Request& r, int n) {
    Reply reply{partial(*file_, r)};
    if (n == 3) {  // cut the third answer halfway through its body
      const size_t head = reply.bytes.find("\r\n\r\n") + 4;
      reply.cut_after = head + (reply.bytes.size() - head) / 2;
      cut_at = *r.first + (reply.bytes.size() - head) / 2;
    }
    return reply;
  });
  Outcome o = stream(server, 8192);
  expect_identical(o);
  EXPECT_EQ(o.reconnects, 1);
  EXPECT_EQ(server.connections(), 2);
  const auto requests = server.requests();
  ASSERT_GT(requests.size(), 4u);
  // The fourth request resumes at the last record that was complete at the cut.
  const auto& ends = o.facts->record_end;
  auto good = std::upper_bound(ends.begin(), ends.end(), cut_at);
  ASSERT_NE(good, ends.begin());
  EXPECT_EQ(*requests[3].first, *(good - 1));
  EXPECT_GT(*requests[3].first, *requests[2].first);
}

TEST_F(HttpStreamTest, ARecordThatFailsItsChecksumIsFetchedAgain) {
  ScriptedServer server([&](const Request& r, int n) {
    Reply reply{partial(*file_, r)};
    if (n == 4) reply.bytes[reply.bytes.size() - 100] ^= 0x20;  // altered on the way, once
    return reply;
  });
  Outcome o = stream(server, 8192);
  expect_identical(o);
  EXPECT_EQ(o.reconnects, 1);
  const auto requests = server.requests();
  ASSERT_GT(requests.size(), 4u);
  // Fetched again from the last good record, which lies inside request 4.
  EXPECT_GE(*requests[4].first, *requests[3].first);
  EXPECT_LE(*requests[4].first, *requests[3].last);
}

TEST_F(HttpStreamTest, AChecksumThatKeepsFailingGivesUpBounded) {
  ScriptedServer server([&](const Request& r, int n) {
    Reply reply{partial(*file_, r)};
    if (n >= 3) reply.bytes[reply.bytes.size() - 1] ^= 0x01;
    return reply;
  });
  Outcome o = stream(server, 8192);
  const std::string e = error_of(o);
  EXPECT_NE(e.find("giving up after 3 attempts"), std::string::npos) << e;
  EXPECT_LT(server.requests().size(), 10u);
}

TEST_F(HttpStreamTest, AServerThatIgnoresRangeIsReadOnceProgressively) {
  ScriptedServer server([](const Request&, int) { return Reply{whole(*file_)}; });
  Outcome o = stream(server, 4096);
  expect_identical(o);
  EXPECT_TRUE(o.range_ignored);
  EXPECT_EQ(server.requests().size(), 1u);
}

TEST_F(HttpStreamTest, AChunkedWholeFileIsReadOnce) {
  ScriptedServer server([](const Request&, int) { return Reply{chunked_whole(*file_, 1000)}; });
  Outcome o = stream(server, 4096);
  expect_identical(o);
  EXPECT_EQ(server.requests().size(), 1u);
}

TEST_F(HttpStreamTest, AChunkedPartialAnswerIsRead) {
  ScriptedServer server([](const Request& r, int) {
    std::string p = partial(*file_, r);
    const size_t head = p.find("\r\n\r\n");
    std::string h = p.substr(0, head);
    h = std::regex_replace(h, std::regex("Content-Length: \\d+"), "Transfer-Encoding: chunked");
    std::string body = p.substr(head + 4);
    std::string out = h + "\r\n\r\n";
    for (size_t at = 0; at < body.size(); at += 777) {
      const std::string c = body.substr(at, 777);
      char size[32];
      std::snprintf(size, sizeof size, "%zx\r\n", c.size());
      out += size + c + "\r\n";
    }
    return Reply{out + "0\r\n\r\n"};
  });
  expect_identical(stream(server, 4096));
}

TEST_F(HttpStreamTest, IgnoredRangeAndADropResumeWithoutALoop) {
  ScriptedServer server([](const Request&, int n) {
    Reply reply{whole(*file_)};
    if (n == 1) reply.cut_after = reply.bytes.size() * 6 / 10;
    return reply;
  });
  Outcome o = stream(server, 4096);
  expect_identical(o);
  EXPECT_EQ(o.reconnects, 1);
  const auto requests = server.requests();
  ASSERT_EQ(requests.size(), 2u);
  EXPECT_FALSE(requests[1].first) << "a server that ignores Range gets a plain GET";
}

TEST_F(HttpStreamTest, ABudgetStopsAtTheDecodersRecordBoundary) {
  ScriptedServer server([](const Request& r, int) { return Reply{partial(*file_, r)}; });
  Outcome o = stream(server, 4096, fast_policy(), Budget::percent_vertices(30));
  ASSERT_TRUE(o.outcome.ok) << o.outcome.error.message;
  EXPECT_EQ(o.outcome.reason, "budget");
  auto index = read_stream_index(
      std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(file_->data()), file_->size()));
  ASSERT_TRUE(index);
  const uint64_t prefix = prefix_for_budget(*index, Budget::percent_vertices(30));
  EXPECT_EQ(o.facts->end_offset, prefix);
  auto expected =
      decode_hcs(std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(file_->data()), prefix));
  ASSERT_TRUE(expected);
  EXPECT_EQ(o.mesh.triangles, expected->triangles);
  EXPECT_LE(*server.requests().back().last + 1, prefix);
}

// Hostile or broken answers: an error naming the URL and the problem, fast.
struct Hostile {
  std::string name;
  std::function<Reply(const Request&, int)> script;
  std::string says;
};

TEST_F(HttpStreamTest, HostileAnswersEndWithAClearErrorNeverAHang) {
  std::string huge = "HTTP/1.1 206 Partial Content\r\n";
  for (int i = 0; i < 4000; ++i) huge += "X-" + std::to_string(i) + ": yyyyyyyyyyyyyyyy\r\n";
  const std::vector<Hostile> cases = {
      {"404",
       [](const Request&, int) {
         return Reply{"HTTP/1.1 404 Not Found\r\nContent-Length: 0\r\n\r\n"};
       },
       "HTTP 404 Not Found"},
      {"html",
       [](const Request&, int) {
         return Reply{
             "HTTP/1.1 200 OK\r\nContent-Type: text/html\r\nContent-Length: "
             "13\r\n\r\n<html></html>"};
       },
       "HTML page"},
      {"html without a type",
       [](const Request&, int) {
         return Reply{"HTTP/1.1 200 OK\r\nContent-Length: 22\r\n\r\n<!DOCTYPE html><html>x"};
       },
       "the body is an HTML page"},
      {"not a stream",
       [](const Request&, int) {
         return Reply{"HTTP/1.1 200 OK\r\nContent-Length: 5\r\n\r\nhello"};
       },
       "not an .hcs stream"},
      {"huge header", [&](const Request&, int) { return Reply{huge + "\r\n"}; },
       "response header is larger"},
      {"bad Content-Range",
       [](const Request&, int) {
         return Reply{
             "HTTP/1.1 206 Partial Content\r\nContent-Range: bytes 0-9\r\n"
             "Content-Length: 10\r\n\r\n0123456789"};
       },
       "has no '/TOTAL'"},
      {"other range",
       [&](const Request& r, int) {
         Request shifted = r;
         shifted.first = r.first.value_or(0) + 1;
         return Reply{partial(*file_, shifted)};
       },
       "the server sent 1-"},
      {"lengths disagree",
       [](const Request&, int) {
         return Reply{
             "HTTP/1.1 206 Partial Content\r\nContent-Range: bytes 0-9/100\r\n"
             "Content-Length: 20\r\n\r\n01234567890123456789"};
       },
       "disagrees with Content-Range"},
      {"not HTTP",
       [](const Request&, int) {
         return Reply{"SSH-2.0-OpenSSH\r\n\r\n", std::string::npos, false, true};
       },
       "malformed HTTP response"},
      {"file shorter than its index",
       [&](const Request& r, int) {
         const std::string cut = file_->substr(0, 3000);
         return Reply{partial(cut, r)};
       },
       "the file holds 3000 bytes but its index describes"},
  };
  for (const Hostile& c : cases) {
    ScriptedServer server(c.script);
    Outcome o = stream(server);
    const std::string e = error_of(o);
    EXPECT_EQ(e.rfind("http://127.0.0.1:", 0), 0u) << c.name << ": " << e;
    EXPECT_NE(e.find(c.says), std::string::npos) << c.name << ": " << e;
    EXPECT_LT(o.seconds, 2.0) << c.name;
    EXPECT_LE(server.requests().size(), 1u) << c.name << ": a final error is not retried";
  }
}

TEST_F(HttpStreamTest, TruncatedAndStalledAnswersAreRetriedThenGiveUp) {
  ReconnectPolicy policy = fast_policy();
  policy.read_timeout = 300ms;
  policy.max_attempts = 2;
  const std::vector<Hostile> cases = {
      {"stalled after the head",
       [&](const Request& r, int) {
         Reply reply{partial(*file_, r)};
         reply.bytes = reply.bytes.substr(0, reply.bytes.find("\r\n\r\n") + 4);
         reply.stall = true;
         return reply;
       },
       "sent nothing for 300 ms"},
      {"always cut short",
       [&](const Request& r, int) {
         Reply reply{partial(*file_, r)};
         reply.cut_after = reply.bytes.find("\r\n\r\n") + 4 + 10;
         return reply;
       },
       "the connection closed after 10 of"},
      {"503",
       [](const Request&, int) { return Reply{"HTTP/1.1 503 Busy\r\nContent-Length: 0\r\n\r\n"}; },
       "HTTP 503"},
  };
  for (const Hostile& c : cases) {
    ScriptedServer server(c.script);
    Outcome o = stream(server, 4096, policy);
    const std::string e = error_of(o);
    EXPECT_NE(e.find("giving up after 2 attempts"), std::string::npos) << c.name << ": " << e;
    EXPECT_NE(e.find(c.says), std::string::npos) << c.name << ": " << e;
    EXPECT_LT(o.seconds, 5.0) << c.name;
    EXPECT_EQ(server.requests().size(), 3u) << c.name;
  }
}

TEST_F(HttpStreamTest, NobodyListeningIsAnErrorAtOnce) {
  uint16_t port;
  {
    ScriptedServer gone([](const Request&, int) { return Reply{}; });
    port = gone.port();
  }
  HttpTarget t;
  t.url = *parse_http_url("http://127.0.0.1:" + std::to_string(port) + "/x.hcs");
  t.reconnect = fast_policy();
  HttpStreamClient client(t);
  DecodedStream decoded;
  client.run(decoded, nullptr);
  ASSERT_TRUE(decoded.outcome());
  EXPECT_FALSE(decoded.outcome()->ok);
  EXPECT_NE(decoded.outcome()->error.message.find("cannot connect"), std::string::npos);
  EXPECT_EQ(client.reconnects(), 0);
}

}  // namespace
}  // namespace meshstream::client
