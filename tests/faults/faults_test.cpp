// Fault tests with the real binaries on loopback: whatever one client does
// (vanish mid-frame, stall half-way through a frame, flood requests), the
// server closes only that client and keeps streaming everyone else byte-exact;
// a server killed with SIGKILL mid-stream and restarted lets the real client
// resume to the same final mesh as an uninterrupted run; a byte flipped in
// transit is caught by the per-record CRC and re-requested; a corrupted cache
// file is detected and re-encoded.
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "tests/client/client_harness.h"
#include "tests/faults/byte_flip_proxy.h"
#include "tests/net/net_harness.h"

namespace {

namespace ct = meshstream::clienttest;
namespace nt = meshstream::nettest;
namespace fs = std::filesystem;
namespace v1 = ::meshstream::v1;
using namespace std::chrono_literals;

class FaultTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new ct::TempDir();
    fs::create_directories(*dir_ / "models");
    // A mesh file (not .hcs), so the server encodes it into its cache.
    ASSERT_EQ(ct::run({ct::tool_bin(), "generate", "demo", "--size", "20000", "-o",
                       *dir_ / "models/demo.ply"},
                      *dir_ / "gen.out", *dir_ / "gen.err"),
              0)
        << ct::read_text(*dir_ / "gen.err");
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }

  // Starts a server on the shared models and its own cache folder.
  static std::unique_ptr<ct::Server> start_server(const std::string& cache,
                                                  std::vector<std::string> extra = {},
                                                  uint16_t port = 0) {
    std::vector<std::string> args{"--models", *dir_ / "models", "--cache", cache};
    args.insert(args.end(), extra.begin(), extra.end());
    auto server = std::make_unique<ct::Server>();
    const std::string logs = cache + "-logs";
    fs::create_directories(logs);
    if (!server->start(args, logs, port)) {
      ADD_FAILURE() << "server did not start: " << server->log();
      return nullptr;
    }
    return server;
  }

  // The one cached stream of the demo model (what every client must get).
  static std::vector<uint8_t> cached_stream(const std::string& cache) {
    for (const auto& entry : fs::directory_iterator(cache)) {
      if (entry.path().extension() == ".hcs") return nt::read_file(entry.path().string());
    }
    return {};
  }

  static nt::StreamResult stream_all(uint16_t port) {
    nt::TestClient c;
    nt::StreamResult r;
    if (!c.connect(port) || !c.hello() || !c.stream("demo")) {
      r.problem = "could not request";
      return r;
    }
    v1::ServerMessage hello;
    if (c.read(hello) != nt::ReadEnd::kMessage || !hello.has_hello()) {
      r.problem = "no hello";
      return r;
    }
    return nt::read_stream(c);
  }

  // meshstream-client HOST:PORT demo --out DIR; exit status.
  static int run_client(const std::string& address, const std::string& out,
                        std::vector<std::string> extra = {}) {
    std::vector<std::string> argv{ct::client_bin(), address, "demo", "--json",
                                  "--quiet",        "--out", out};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return ct::run(argv, out + ".events", out + ".err");
  }

  static ct::TempDir* dir_;
};
ct::TempDir* FaultTest::dir_ = nullptr;

TEST_F(FaultTest, VanishingAndStallingClientsLeaveOthersByteExact) {
  const std::string cache = *dir_ / "cache-vanish";
  auto server = start_server(cache, {"--handshake-timeout-ms", "700", "--idle-timeout-ms", "900"});
  ASSERT_TRUE(server);
  const std::vector<uint8_t> expected = cached_stream(cache);
  ASSERT_FALSE(expected.empty());

  v1::ClientMessage hello;
  hello.mutable_hello()->set_protocol_version(meshstream::proto::kProtocolVersion);
  v1::ClientMessage request;
  request.mutable_stream()->set_model("demo");
  const std::vector<uint8_t> hello_frame = meshstream::proto::encode_frame(hello);
  const std::vector<uint8_t> request_frame = meshstream::proto::encode_frame(request);
  auto half = [](const std::vector<uint8_t>& f) {
    return std::vector<uint8_t>(f.begin(), f.begin() + f.size() / 2);
  };

  // 40 clients vanish: half a Hello, half a request, or mid-stream; every
  // other one resets the connection (SO_LINGER 0) instead of closing.
  for (int i = 0; i < 40; ++i) {
    nt::TestClient c;
    ASSERT_TRUE(c.connect(server->port()));
    if (i % 3 == 0) {
      c.send_raw(half(hello_frame));
    } else if (i % 3 == 1) {
      c.send_raw(hello_frame);
      c.send_raw(half(request_frame));
    } else {
      c.send_raw(hello_frame);
      c.send_raw(request_frame);
      v1::ServerMessage m;
      c.read(m, 2000ms);
      c.read(m, 2000ms);
    }
    if (i % 2 == 0) {
      linger l{1, 0};
      ::setsockopt(c.fd(), SOL_SOCKET, SO_LINGER, &l, sizeof l);
    }
  }
  // Two stall half-way through a frame and stay connected.
  nt::TestClient stall_hello, stall_request;
  ASSERT_TRUE(stall_hello.connect(server->port()));
  ASSERT_TRUE(stall_request.connect(server->port()));
  ASSERT_TRUE(stall_hello.send_raw(half(hello_frame)));
  ASSERT_TRUE(stall_request.send_raw(hello_frame));
  ASSERT_TRUE(stall_request.send_raw(half(request_frame)));

  // Meanwhile others stream the whole model, byte-exact.
  for (int i = 0; i < 3; ++i) {
    const nt::StreamResult r = stream_all(server->port());
    ASSERT_TRUE(r.ok) << r.problem;
    EXPECT_EQ(r.bytes, expected) << "stream " << i << " differs from the cached stream";
  }
  // The stallers are closed by the server's deadlines (not left hanging).
  EXPECT_TRUE(stall_hello.wait_closed(5s))
      << "half a Hello: not closed after the handshake timeout";
  EXPECT_TRUE(stall_request.wait_closed(5s)) << "half a request: not closed after the idle timeout";
  const nt::StreamResult after = stream_all(server->port());
  ASSERT_TRUE(after.ok) << after.problem;
  EXPECT_EQ(after.bytes, expected);
}

TEST_F(FaultTest, FloodsAndGarbageAreRefusedWhileOthersStream) {
  const std::string cache = *dir_ / "cache-flood";
  auto server = start_server(cache);
  ASSERT_TRUE(server);
  const std::vector<uint8_t> expected = cached_stream(cache);

  // One client floods: 5000 requests (streams, lists, cancels, unknown
  // models) in one burst, never reading its replies.
  nt::TestClient flood;
  ASSERT_TRUE(flood.connect(server->port(), 4096));
  std::vector<uint8_t> burst;
  v1::ClientMessage hello;
  hello.mutable_hello()->set_protocol_version(meshstream::proto::kProtocolVersion);
  meshstream::proto::append_frame(hello, burst);
  for (int i = 0; i < 5000; ++i) {
    v1::ClientMessage m;
    switch (i % 4) {
      case 0:
        m.mutable_stream()->set_model("demo");
        break;
      case 1:
        m.mutable_list_models();
        break;
      case 2:
        m.mutable_cancel();
        break;
      default:
        m.mutable_stream()->set_model("no-such-model-" + std::to_string(i));
        break;
    }
    meshstream::proto::append_frame(m, burst);
  }
  std::thread flooder([&] { flood.send_raw(burst); });

  // Garbage: an oversized length prefix, a frame that is not a message, an
  // unknown protocol version. Each gets an error (or a close), nothing more.
  const std::vector<std::vector<uint8_t>> bad = {
      {0xff, 0xff, 0xff, 0xff, 0x0f},
      {0x04, 0xff, 0xff, 0xff, 0xff},
      {0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x01},
  };
  for (const auto& bytes : bad) {
    nt::TestClient c;
    ASSERT_TRUE(c.connect(server->port()));
    c.send_raw(bytes);
    std::vector<v1::ServerMessage> seen;
    EXPECT_TRUE(c.wait_closed(5s, &seen)) << "a client sending garbage was not closed";
  }
  {
    nt::TestClient c;
    ASSERT_TRUE(c.connect(server->port()));
    ASSERT_TRUE(c.hello(999));
    std::vector<v1::ServerMessage> seen;
    EXPECT_TRUE(c.wait_closed(5s, &seen));
    ASSERT_FALSE(seen.empty());
    EXPECT_TRUE(seen.back().has_error());
  }
  for (int i = 0; i < 3; ++i) {
    const nt::StreamResult r = stream_all(server->port());
    ASSERT_TRUE(r.ok) << r.problem;
    EXPECT_EQ(r.bytes, expected);
  }
  flood.close();
  flooder.join();
  const nt::StreamResult after = stream_all(server->port());
  ASSERT_TRUE(after.ok) << after.problem;
  EXPECT_EQ(after.bytes, expected);
}

TEST_F(FaultTest, ServerKilledMidStreamClientResumesToTheSameFinalMesh) {
  const std::string cache = *dir_ / "cache-kill";
  auto reference_server = start_server(cache);
  ASSERT_TRUE(reference_server);
  const std::string reference = *dir_ / "uninterrupted";
  ASSERT_EQ(run_client(reference_server->address(), reference), 0)
      << ct::read_text(reference + ".err");
  reference_server.reset();

  const uint16_t port = ct::free_port();
  auto server = start_server(cache, {"--rate", "30000", "--max-chunk-bytes", "1024"}, port);
  ASSERT_TRUE(server);
  const std::string out = *dir_ / "killed";
  ct::Child client;
  ASSERT_TRUE(
      client.start({ct::client_bin(), server->address(), "demo", "--json", "--quiet", "--out", out},
                   out + ".events", out + ".err"));
  for (int kill = 0; kill < 2; ++kill) {
    // Wait for some progress, then SIGKILL the server and restart it.
    const size_t before =
        ct::of_kind(ct::parse_events(ct::read_text(out + ".events")), "refinement").size();
    const auto deadline = ct::Clock::now() + 20s;
    while (ct::Clock::now() < deadline &&
           ct::of_kind(ct::parse_events(ct::read_text(out + ".events")), "refinement").size() <
               before + 3) {
      std::this_thread::sleep_for(10ms);
    }
    ASSERT_TRUE(ct::of_kind(ct::parse_events(ct::read_text(out + ".events")), "done").empty())
        << "the stream finished before kill " << kill << " (not mid-stream)";
    server->kill_hard();
    std::this_thread::sleep_for(300ms);
    server = start_server(
        cache,
        kill == 0 ? std::vector<std::string>{"--rate", "30000", "--max-chunk-bytes", "1024"}
                  : std::vector<std::string>{},
        port);
    ASSERT_TRUE(server);
  }
  const auto status = client.wait(60s);
  ASSERT_TRUE(status.has_value()) << "client did not finish";
  ASSERT_EQ(*status, 0) << ct::read_text(out + ".err");
  const auto events = ct::parse_events(ct::read_text(out + ".events"));
  ASSERT_FALSE(events.empty());
  EXPECT_GE(events.back()["reconnects"].get<int>(), 1);
  EXPECT_EQ(events.back()["reason"], "complete");
  EXPECT_EQ(ct::read_text(out + "/final.ply"), ct::read_text(reference + "/final.ply"))
      << "the final mesh after two SIGKILLs differs from the uninterrupted run";
}

TEST_F(FaultTest, ByteFlippedInTransitIsCaughtAndReRequested) {
  const std::string cache = *dir_ / "cache-flip";
  auto server = start_server(cache, {"--max-chunk-bytes", "2048"});
  ASSERT_TRUE(server);
  const std::string reference = *dir_ / "flip-reference";
  ASSERT_EQ(run_client(server->address(), reference), 0) << ct::read_text(reference + ".err");

  meshstream::faulttest::ByteFlipProxy proxy(server->port(), 6);
  const std::string out = *dir_ / "flipped";
  const int status =
      run_client("127.0.0.1:" + std::to_string(proxy.port()), out, {"--max-chunk-bytes", "2048"});
  ASSERT_TRUE(proxy.flipped()) << "the proxy never corrupted a chunk (stream too short?)";
  const std::string err = ct::read_text(out + ".err");
  ASSERT_EQ(status, 0)
      << "CLIENT LACKS RE-REQUEST ON CHECKSUM FAILURE: a record whose CRC-32 does not match "
         "should make meshstream-client reconnect and resume from the last good record; "
         "instead it exited "
      << status << ": " << err;
  EXPECT_GE(proxy.connections(), 2) << "the client finished without re-requesting";
  EXPECT_EQ(ct::read_text(out + "/final.ply"), ct::read_text(reference + "/final.ply"));
}

TEST_F(FaultTest, CorruptedCacheFileIsDetectedAndReEncoded) {
  const std::string cache = *dir_ / "cache-corrupt";
  std::vector<uint8_t> good;
  {
    auto server = start_server(cache);
    ASSERT_TRUE(server);
    const nt::StreamResult r = stream_all(server->port());
    ASSERT_TRUE(r.ok) << r.problem;
    good = r.bytes;
    ASSERT_EQ(server->stop(), 0);
  }
  std::string cached;
  for (const auto& entry : fs::directory_iterator(cache)) {
    if (entry.path().extension() == ".hcs") cached = entry.path().string();
  }
  ASSERT_FALSE(cached.empty());
  ASSERT_EQ(nt::read_file(cached), good);
  // Flip one byte in the middle (inside a record payload).
  std::vector<uint8_t> bytes = good;
  bytes[bytes.size() / 2] ^= 0x01;
  nt::write_file(cached, bytes);
  {
    auto server = start_server(cache);
    ASSERT_TRUE(server);
    const nt::StreamResult r = stream_all(server->port());
    ASSERT_TRUE(r.ok) << r.problem;
    EXPECT_EQ(r.bytes, good) << "a corrupted cache entry was served (or re-encoded differently)";
    EXPECT_EQ(nt::read_file(cached), good) << "the corrupted cache file was not replaced";
    ASSERT_EQ(server->stop(), 0);
  }
  // A truncated cache file too.
  nt::write_file(cached, std::vector<uint8_t>(good.begin(), good.begin() + good.size() / 3));
  {
    auto server = start_server(cache);
    ASSERT_TRUE(server);
    const nt::StreamResult r = stream_all(server->port());
    ASSERT_TRUE(r.ok) << r.problem;
    EXPECT_EQ(r.bytes, good);
  }
}

}  // namespace
