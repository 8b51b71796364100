// --metrics: the real meshstream-server serving /metrics and /healthz over
// HTTP, scraped with the real curl after real streams on loopback. Checks
// that every counter moved by exactly what the clients saw, that the text is
// valid Prometheus exposition (strict line checker, prometheus_text.h), and
// that garbage requests get an answer or a close, never a crash or a stall
// of the streaming port.
#include <gtest/gtest.h>

#include <random>

#include "server/synthetic_stream.h"
#include "tests/net/greeted_client.h"
#include "tests/net/net_harness.h"
#include "tests/net/prometheus_text.h"

namespace meshstream::nettest {
namespace {

namespace fs = std::filesystem;

const ModelsFolder& models_folder = register_models_folder("ms_metrics_");

struct MetricsModels {
  std::string dir;
  std::vector<uint8_t> small;
  std::vector<uint8_t> big;
};

const MetricsModels& models() {
  static const MetricsModels m = [] {
    MetricsModels out;
    out.dir = models_folder.create();
    server::SyntheticStreamOptions small;
    small.records = 40;
    small.payload_bytes = 120000;
    out.small = server::make_synthetic_hcs(small);
    server::SyntheticStreamOptions big;
    big.records = 300;
    big.payload_bytes = 16 << 20;
    big.seed = 3;
    out.big = server::make_synthetic_hcs(big);
    write_file(out.dir + "/small.hcs", out.small);
    write_file(out.dir + "/big.hcs", out.big);
    // Not a stream: listed as failed.
    write_file(out.dir + "/broken.hcs", std::vector<uint8_t>{'M', 'H', 'C', 'S', 1, 0});
    return out;
  }();
  return m;
}

class MetricsEndpointTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!have_curl()) GTEST_SKIP() << "curl is not installed (Debian package curl)";
    ASSERT_TRUE(server_.start(
        {"--models", models().dir, "--cache", "none", "--threads", "2", "--metrics", "127.0.0.1:0"},
        models().dir + "/" + ::testing::UnitTest::GetInstance()->current_test_info()->name() +
            ".log"))
        << server_.log();
    metrics_port_ = server_.read_metrics_port();
    ASSERT_NE(metrics_port_, 0) << "no 'metrics on HOST:PORT' line on stdout";
  }
  std::string url(const std::string& path) const {
    return "http://127.0.0.1:" + std::to_string(metrics_port_) + path;
  }
  PrometheusText scrape() {
    const HttpAnswer answer = curl(url("/metrics"));
    EXPECT_EQ(answer.status, 200);
    EXPECT_EQ(answer.content_type, "text/plain; version=0.0.4; charset=utf-8");
    PrometheusText text = parse_prometheus(answer.body);
    EXPECT_EQ(text.problem, "") << answer.body;
    return text;
  }
  // Scrapes until no session is open (the server counts a session's end
  // when its socket is gone, a moment after the client's close).
  PrometheusText scrape_when_idle() {
    PrometheusText text;
    for (int i = 0; i < 100; ++i) {
      text = scrape();
      if (text.value("meshstream_sessions_open") == 0) break;
      std::this_thread::sleep_for(50ms);
    }
    return text;
  }
  ServerProcess server_;
  uint16_t metrics_port_ = 0;
};

TEST_F(MetricsEndpointTest, StartsAtZeroWithEveryFamilyAndModelsReady) {
  const PrometheusText t = scrape();
  EXPECT_EQ(t.types.at("meshstream_sessions_open"), "gauge");
  EXPECT_EQ(t.types.at("meshstream_bytes_sent_total"), "counter");
  EXPECT_EQ(t.types.at("meshstream_streams_total"), "counter");
  EXPECT_EQ(t.types.at("meshstream_errors_total"), "counter");
  EXPECT_EQ(t.types.at("meshstream_models"), "gauge");
  EXPECT_EQ(t.types.at("meshstream_encode_queue_length"), "gauge");
  EXPECT_EQ(t.value("meshstream_sessions_open"), 0);
  EXPECT_EQ(t.value("meshstream_bytes_sent_total"), 0);
  for (const char* outcome : {"complete", "budget", "cancelled", "interrupted"}) {
    EXPECT_EQ(t.value(std::string("meshstream_streams_total{outcome=\"") + outcome + "\"}"), 0);
  }
  for (const char* code : {"protocol_violation", "version_mismatch", "frame_too_large",
                           "malformed_frame", "unknown_model", "invalid_request", "busy", "timeout",
                           "shutting_down", "internal", "not_ready", "model_failed"}) {
    EXPECT_EQ(t.value(std::string("meshstream_errors_total{code=\"") + code + "\"}"), 0) << code;
  }
  EXPECT_EQ(t.value("meshstream_models{state=\"ready\"}"), 2);
  EXPECT_EQ(t.value("meshstream_models{state=\"queued\"}"), 0);
  EXPECT_EQ(t.value("meshstream_models{state=\"encoding\"}"), 0);
  EXPECT_EQ(t.value("meshstream_models{state=\"failed\"}"), 1);
  EXPECT_EQ(t.value("meshstream_encode_queue_length"), 0);
}

TEST_F(MetricsEndpointTest, CountersMoveByWhatTheClientsReceived) {
  const uint64_t small_total = models().small.size();
  uint64_t expected_bytes = 0;
  {
    // Two whole streams on one connection, then one cut by a budget.
    TestClient a = greeted_client(server_.port());
    for (int i = 0; i < 2; ++i) {
      ASSERT_TRUE(a.stream("small"));
      const StreamResult r = read_stream(a);
      ASSERT_TRUE(r.ok) << r.problem;
      ASSERT_EQ(r.bytes.size(), small_total);
      expected_bytes += r.bytes.size();
    }
    v1::StreamRequest budgeted;
    budgeted.set_model("small");
    budgeted.mutable_budget()->set_bytes(small_total / 2);
    ASSERT_TRUE(a.stream(budgeted));
    const StreamResult r = read_stream(a);
    ASSERT_TRUE(r.ok) << r.problem;
    ASSERT_EQ(r.end.reason(), v1::StreamEnd::BUDGET);
    expected_bytes += r.bytes.size();
  }
  {
    // An unknown model (an error frame, the connection stays), then a
    // cancelled stream of the big model.
    TestClient b = greeted_client(server_.port());
    ASSERT_TRUE(b.stream("no-such-model"));
    v1::ServerMessage m;
    ASSERT_EQ(b.read(m), ReadEnd::kMessage);
    ASSERT_TRUE(m.has_error());
    ASSERT_TRUE(b.stream("broken"));  // a failed model: MODEL_FAILED
    ASSERT_EQ(b.read(m), ReadEnd::kMessage);
    ASSERT_TRUE(m.has_error());
    ASSERT_EQ(m.error().code(), v1::Error::MODEL_FAILED);
    ASSERT_TRUE(b.stream("big"));
    ASSERT_EQ(b.read(m), ReadEnd::kMessage);  // header (maybe with its first chunk)
    ASSERT_TRUE(b.cancel());
    uint64_t received = 0;
    while (true) {
      ASSERT_EQ(b.read(m), ReadEnd::kMessage);
      if (m.has_chunk()) received += m.chunk().data().size();
      if (m.has_end()) break;
    }
    ASSERT_EQ(m.end().reason(), v1::StreamEnd::CANCELLED);
    expected_bytes += m.end().bytes_sent();
  }
  const PrometheusText t = scrape_when_idle();
  EXPECT_EQ(t.value("meshstream_sessions_open"), 0);
  EXPECT_EQ(t.value("meshstream_sessions_total"), 2);
  EXPECT_EQ(t.value("meshstream_bytes_sent_total"), double(expected_bytes));
  EXPECT_EQ(t.value("meshstream_streams_total{outcome=\"complete\"}"), 2);
  EXPECT_EQ(t.value("meshstream_streams_total{outcome=\"budget\"}"), 1);
  EXPECT_EQ(t.value("meshstream_streams_total{outcome=\"cancelled\"}"), 1);
  EXPECT_EQ(t.value("meshstream_streams_total{outcome=\"interrupted\"}"), 0);
  EXPECT_EQ(t.value("meshstream_errors_total{code=\"unknown_model\"}"), 1);
  EXPECT_EQ(t.value("meshstream_errors_total{code=\"invalid_request\"}"), 0);
  EXPECT_EQ(t.value("meshstream_errors_total{code=\"model_failed\"}"), 1);

  // A client that leaves mid-stream: interrupted, and the server counted at
  // least what that client read and at most the whole stream.
  uint64_t read_before_leaving = 0;
  {
    TestClient c = greeted_client(server_.port());
    ASSERT_TRUE(c.stream("big"));
    v1::ServerMessage m;
    while (read_before_leaving < 100000) {
      ASSERT_EQ(c.read(m), ReadEnd::kMessage);
      if (m.has_chunk()) read_before_leaving += m.chunk().data().size();
      ASSERT_FALSE(m.has_end());
    }
    // While it streams, it is an open session.
    EXPECT_EQ(scrape().value("meshstream_sessions_open"), 1);
  }
  const PrometheusText after = scrape_when_idle();
  EXPECT_EQ(after.value("meshstream_sessions_open"), 0);
  EXPECT_EQ(after.value("meshstream_sessions_total"), 3);
  EXPECT_EQ(after.value("meshstream_streams_total{outcome=\"interrupted\"}"), 1);
  const double interrupted_bytes = after.value("meshstream_bytes_sent_total") - expected_bytes;
  EXPECT_GE(interrupted_bytes, double(read_before_leaving));
  EXPECT_LT(interrupted_bytes, double(models().big.size()));
}

TEST_F(MetricsEndpointTest, HealthzAnswersOkAndOtherPathsAndMethodsAreRefused) {
  const HttpAnswer health = curl(url("/healthz"));
  EXPECT_EQ(health.status, 200);
  EXPECT_EQ(health.body, "ok\n");
  EXPECT_EQ(curl(url("/metrics?x=1")).status, 200);  // a query string is ignored
  EXPECT_EQ(curl(url("/")).status, 404);
  EXPECT_EQ(curl(url("/metrics/x")).status, 404);
  EXPECT_EQ(curl(url("/healthz"), "-X DELETE").status, 405);
  const HttpAnswer head = curl(url("/metrics"), "-I");
  EXPECT_EQ(head.status, 200);
  EXPECT_NE(head.body.find("Content-Length:"), std::string::npos) << head.body;
  EXPECT_EQ(head.body.find("meshstream_"), std::string::npos) << "HEAD sent a body";
  // A request with a body is refused, not read.
  EXPECT_EQ(curl(url("/metrics"), "-X POST -d abc").status, 400);
}

// Sends `bytes` on a fresh connection to `port`, half-closes, and reads the
// answer until the server closes or `timeout`; the answer ("" = closed).
std::string raw_exchange(uint16_t port, const std::string& bytes, std::chrono::milliseconds timeout,
                         bool half_close = true) {
  TestClient c;
  if (!c.connect(port)) return "connect failed";
  c.send_raw(std::vector<uint8_t>(bytes.begin(), bytes.end()));
  if (half_close) ::shutdown(c.fd(), SHUT_WR);
  std::string answer;
  const auto deadline = Clock::now() + timeout;
  while (Clock::now() < deadline) {
    pollfd p{c.fd(), POLLIN, 0};
    if (::poll(&p, 1, 20) <= 0) continue;
    char buffer[4096];
    const ssize_t n = ::recv(c.fd(), buffer, sizeof buffer, 0);
    if (n <= 0) return answer;
    answer.append(buffer, size_t(n));
  }
  return answer + "<timeout>";
}

TEST_F(MetricsEndpointTest, GarbageRequestsGetAnAnswerOrACloseAndNothingBreaks) {
  // Connections that send half a request and then nothing: they must not
  // stop anyone else from being answered while they hang.
  std::vector<TestClient> hanging(8);
  for (auto& h : hanging) {
    ASSERT_TRUE(h.connect(metrics_port_));
    const std::string half = "GET /metrics HTTP/1.1\r\nHost: x\r\n";
    h.send_raw(std::vector<uint8_t>(half.begin(), half.end()));
  }
  std::mt19937 random(19);
  const std::vector<std::string> shapes = {
      "GET /metrics HTTP/1.1\r\nHost: x\r\nContent-Length: -1\r\n\r\n",
      "GET /metrics HTTP/9.9\r\n\r\n",
      "GET\r\n\r\n",
      "\r\n\r\n\r\n",
      "GET /metrics HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\nzz\r\n",
      "GET /" + std::string(20000, 'a') + " HTTP/1.1\r\n\r\n",
      "GET /healthz HTTP/1.1\r\nX: " + std::string(20000, 'b') + "\r\n\r\n",
      "GET /healthz HTTP/1.1\r\nHost: x\r\n\r\nGET /healthz HTTP/1.1\r\nbroken\r\n\r\n",
      std::string("GET /healthz\0 HTTP/1.1\r\n\r\n", 26),
  };
  int answered_400 = 0;
  for (int i = 0; i < 200; ++i) {
    std::string request;
    if (i < int(shapes.size())) {
      request = shapes[size_t(i)];
    } else if (i % 2 == 0) {
      // Random bytes.
      request.resize(random() % 3000 + 1);
      for (char& c : request) c = static_cast<char>(random());
    } else {
      // A valid request with a few bytes flipped.
      request = "GET /metrics HTTP/1.1\r\nHost: 127.0.0.1\r\nAccept: */*\r\n\r\n";
      for (int k = 0; k < 3; ++k) request[random() % request.size()] = static_cast<char>(random());
    }
    const std::string answer = raw_exchange(metrics_port_, request, 3s);
    ASSERT_EQ(answer.find("<timeout>"), std::string::npos)
        << "no answer and no close within 3 s for request " << i;
    if (!answer.empty()) {
      EXPECT_EQ(answer.rfind("HTTP/1.1 ", 0), 0u) << "request " << i << " got: " << answer;
    }
    if (answer.rfind("HTTP/1.1 400", 0) == 0) ++answered_400;
  }
  EXPECT_GT(answered_400, 50);  // garbage is told so, not only dropped
  // Still serving: health, metrics (valid text) and streams.
  EXPECT_EQ(curl(url("/healthz")).status, 200);
  EXPECT_EQ(scrape().value("meshstream_sessions_total"), 0);
  TestClient c = greeted_client(server_.port());
  ASSERT_TRUE(c.stream("small"));
  const StreamResult r = read_stream(c);
  EXPECT_TRUE(r.ok) << r.problem;
  EXPECT_EQ(r.bytes, models().small);
}

TEST(MetricsOptionTest, BadAddressIsAUsageErrorAndABusyPortFailsAtOnce) {
  const std::string bin = server_binary();
  const std::string dir = models().dir;
  EXPECT_EQ(WEXITSTATUS(std::system(
                (bin + " --models " + dir + " --metrics nope > /dev/null 2>&1").c_str())),
            2);
  ServerProcess first;
  ASSERT_TRUE(first.start({"--models", dir, "--cache", "none", "--metrics", "127.0.0.1:0"},
                          dir + "/first.log"))
      << first.log();
  const uint16_t taken = first.read_metrics_port();
  ASSERT_NE(taken, 0);
  const std::string err = dir + "/busy.err";
  const int status =
      std::system((bin + " --models " + dir + " --cache none --listen 127.0.0.1:0 --metrics " +
                   "127.0.0.1:" + std::to_string(taken) + " > /dev/null 2> " + err)
                      .c_str());
  EXPECT_EQ(WEXITSTATUS(status), 1);
  std::ifstream in(err);
  const std::string message((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(message.find("--metrics: cannot listen on 127.0.0.1:" + std::to_string(taken)),
            std::string::npos)
      << message;
}

}  // namespace
}  // namespace meshstream::nettest

namespace meshstream::nettest {
namespace {

// The checker itself must be able to fail, or the scrapes above prove nothing.
TEST(PrometheusTextCheckerTest, RefusesWhatPrometheusWouldRefuse) {
  const std::string good =
      "# HELP a_total A.\n# TYPE a_total counter\na_total{x=\"1\"} 2\na_total{x=\"2\"} 3\n";
  EXPECT_EQ(parse_prometheus(good).problem, "");
  EXPECT_EQ(parse_prometheus(good).value("a_total{x=\"2\"}"), 3);
  const std::vector<std::string> bad = {
      "# HELP a_total A.\n# TYPE a_total counter\na_total 2",  // no final newline
      "# TYPE a_total counter\na_total 2\n",                   // no HELP
      "# HELP a A.\n# TYPE a counter\na 2\n",                  // counter without _total
      "# HELP a A.\n# TYPE a gauge\na two\n",                  // not a number
      "# HELP a A.\n# TYPE a gauge\na{x=1} 2\n",               // unquoted label value
      "# HELP a A.\n# TYPE a gauge\na 2\na 3\n",               // series twice
      "# HELP a A.\n# TYPE a gauge\n# HELP b B.\n# TYPE b gauge\na 1\nb 1\na{y=\"\"} 2\n",
      "# HELP a A.\n# TYPE a gauge\n# random comment\na 1\n",  // stray comment
      "# HELP 1a A.\n# TYPE 1a gauge\n1a 1\n",                 // bad name
  };
  for (const std::string& text : bad) EXPECT_NE(parse_prometheus(text).problem, "") << text;
}

}  // namespace
}  // namespace meshstream::nettest
