// N real meshstream-server processes on one --cache folder
// (server/cache_lock.h): started together on a cold cache they encode each
// model once, leave no temporary or broken entry (also when one is killed
// while encoding), and every server, also one with a cache of its own,
// streams byte-identical bytes for the same input and options.
#include <gtest/gtest.h>

#include "tests/deploy/deploy_harness.h"

namespace meshstream::deploytest {
namespace {

int count_lines(const std::string& text, const std::regex& pattern) {
  int n = 0;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) n += std::regex_search(line, pattern) ? 1 : 0;
  return n;
}

// The whole stream of `model` as one client receives it from `port`.
std::vector<uint8_t> stream_of(uint16_t port, const std::string& model) {
  nettest::TestClient c;
  EXPECT_TRUE(c.connect(port));
  EXPECT_TRUE(c.hello());
  v1::ServerMessage hello;
  EXPECT_EQ(c.read(hello), nettest::ReadEnd::kMessage);
  EXPECT_TRUE(c.stream(model));
  const nettest::StreamResult r = nettest::read_stream(c);
  EXPECT_TRUE(r.ok) << r.problem;
  return r.bytes;
}

std::vector<std::string> cache_files(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

class SharedCacheTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(make_model(tmp_ / "models", "knot", 6000), "");
    ASSERT_EQ(make_model(tmp_ / "models", "big", 60000), "");
  }
  std::vector<std::string> server_args(const std::string& cache) const {
    return {"--models", tmp_ / "models", "--cache", cache, "--threads", "1"};
  }
  clienttest::TempDir tmp_;
};

TEST_F(SharedCacheTest, ServersStartedTogetherEncodeEachModelOnceAndServeTheSameBytes) {
  const std::string cache = tmp_ / "cache";
  std::vector<std::unique_ptr<FleetServer>> fleet;
  std::string problem;
  ASSERT_TRUE(start_fleet(fleet, 3, server_args(cache), tmp_.path(), problem)) << problem;
  std::string logs;
  for (const auto& s : fleet) logs += s->process.log();
  for (const std::string model : {"knot", "big"}) {
    EXPECT_EQ(count_lines(logs, std::regex(": encoded .*" + model + "\\.ply")), 1)
        << model << " must be encoded by exactly one of the 3 servers:\n"
        << logs;
    EXPECT_EQ(count_lines(logs, std::regex(": from cache .*" + model + "\\.ply")), 2) << logs;
  }
  // Two entries and their locks; no temporary file left.
  const std::vector<std::string> files = cache_files(cache);
  ASSERT_EQ(files.size(), 4u) << ::testing::PrintToString(files);
  for (const std::string& f : files) {
    EXPECT_TRUE(f.ends_with(".hcs") || f.ends_with(".hcs.lock")) << f;
  }
  // A fourth server with a cache of its own encodes the same input again.
  nettest::ServerProcess alone;
  ASSERT_TRUE(alone.start(server_args(tmp_ / "cache-alone"), tmp_ / "alone.log", 60s))
      << alone.log();
  EXPECT_EQ(count_lines(alone.log(), std::regex(": encoded ")), 2) << alone.log();
  for (const std::string model : {"knot", "big"}) {
    const std::vector<uint8_t> first = stream_of(fleet[0]->process.port(), model);
    ASSERT_GT(first.size(), 1000u);
    for (size_t i = 1; i < fleet.size(); ++i) {
      EXPECT_TRUE(stream_of(fleet[i]->process.port(), model) == first)
          << model << ": server " << i + 1 << " streams other bytes than server 1";
    }
    EXPECT_TRUE(stream_of(alone.port(), model) == first)
        << model << ": a server with its own cache streams other bytes";
    // What they stream is the shared cache entry itself.
    bool found = false;
    for (const std::string& f : files) {
      if (!f.ends_with(".hcs")) continue;  // named by the input's content hash
      if (nettest::read_file(cache + "/" + f) == first) found = true;
    }
    EXPECT_TRUE(found) << model << ": no cache entry holds the streamed bytes";
  }
}

TEST_F(SharedCacheTest, AServerKilledWhileEncodingLeavesNothingBroken) {
  const std::string cache = tmp_ / "cache";
  fs::create_directories(cache);
  // Kill the first server as soon as it holds a lock: in the middle of an
  // encode (its lock is released by the kernel, its temporary file stays).
  clienttest::Child first;
  ASSERT_TRUE(first.start({clienttest::server_bin(), "--listen", "127.0.0.1:0", "--models",
                           tmp_ / "models", "--cache", cache, "--threads", "1"},
                          tmp_ / "first.out", tmp_ / "first.err"));
  bool locked = false;
  const auto deadline = Clock::now() + 60s;
  while (!locked && Clock::now() < deadline) {
    for (const std::string& f : cache_files(cache)) locked |= f.ends_with(".lock");
    if (!locked) std::this_thread::sleep_for(2ms);
  }
  ASSERT_TRUE(locked) << "the first server never took a cache lock: "
                      << read_text(tmp_ / "first.err");
  first.kill_now();
  // Then two together: both come up, each model is encoded by one of them,
  // and they stream the same bytes.
  std::vector<std::unique_ptr<FleetServer>> fleet;
  std::string problem;
  ASSERT_TRUE(start_fleet(fleet, 2, server_args(cache), tmp_.path(), problem)) << problem;
  const std::string logs = fleet[0]->process.log() + fleet[1]->process.log();
  EXPECT_EQ(count_lines(logs, std::regex("initial models done: 2 ready, 0 failed")), 2) << logs;
  for (const std::string model : {"knot", "big"}) {
    EXPECT_LE(count_lines(logs, std::regex(": encoded .*" + model + "\\.ply")), 1) << logs;
    EXPECT_TRUE(stream_of(fleet[0]->process.port(), model) ==
                stream_of(fleet[1]->process.port(), model))
        << model;
  }
}

// A server still encoding the models it found at start is not sent
// clients: HAProxy's check (/healthz) says 503 until they are done, while
// /metrics shows them queued or encoding.
TEST_F(SharedCacheTest, HealthzSays503UntilTheModelsFoundAtStartAreDone) {
  if (!nettest::have_curl()) GTEST_SKIP() << "curl is not installed (Debian package curl)";
  nettest::ServerProcess server;
  std::vector<std::string> args = server_args(tmp_ / "cache");
  args.insert(args.end(), {"--metrics", "127.0.0.1:0", "--encoders", "1"});
  ASSERT_TRUE(server.start(args, tmp_ / "health.log", 30s, nettest::ServerProcess::Wait::kPort))
      << server.log();
  const uint16_t metrics = server.read_metrics_port();
  ASSERT_NE(metrics, 0);
  const std::string base = "http://127.0.0.1:" + std::to_string(metrics);
  const nettest::HttpAnswer early = nettest::curl(base + "/healthz");
  const nettest::PrometheusText early_metrics =
      nettest::parse_prometheus(nettest::curl(base + "/metrics").body);
  ASSERT_TRUE(server.wait_log("initial models done", 60s)) << server.log();
  // The 60k-triangle model takes more than a second to encode on a cold
  // cache, so the first answers came while it was not ready.
  EXPECT_EQ(early.status, 503) << early.body;
  EXPECT_EQ(early.body, "loading models\n");
  EXPECT_EQ(early_metrics.problem, "");
  EXPECT_LT(early_metrics.value("meshstream_models{state=\"ready\"}"), 2);
  EXPECT_GE(early_metrics.value("meshstream_models{state=\"queued\"}") +
                early_metrics.value("meshstream_models{state=\"encoding\"}"),
            1);
  const nettest::HttpAnswer later = nettest::curl(base + "/healthz");
  EXPECT_EQ(later.status, 200);
  const nettest::PrometheusText done =
      nettest::parse_prometheus(nettest::curl(base + "/metrics").body);
  EXPECT_EQ(done.value("meshstream_models{state=\"ready\"}"), 2);
  EXPECT_EQ(done.value("meshstream_encode_queue_length"), 0);
}

}  // namespace
}  // namespace meshstream::deploytest
