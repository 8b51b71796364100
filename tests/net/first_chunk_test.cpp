// First chunks before bulk (server/first_chunk_gate.h): the gate's rules on
// their own, and through the real server that a hold never outlives the
// streams that caused it (every way a starting stream can end releases it),
// so a long --first-chunk-hold-ms never stalls later streams.
#include <gtest/gtest.h>

#include <atomic>

#include "server/first_chunk_gate.h"
#include "server/synthetic_stream.h"
#include "tests/net/greeted_client.h"
#include "tests/net/net_harness.h"

namespace meshstream::nettest {
namespace {

namespace fs = std::filesystem;
using server::FirstChunkGate;
using GateClock = FirstChunkGate::Clock;

// ---------------------------------------------------------------- the gate

TEST(FirstChunkGate, HoldsBulkOnlyWhileAStreamIsStarting) {
  FirstChunkGate gate(std::chrono::milliseconds(50));
  int wakes = 0;
  gate.add_waker([&] { ++wakes; });
  const auto t0 = GateClock::now();
  EXPECT_FALSE(gate.hold_bulk_until(t0));
  gate.stream_starting(t0);
  ASSERT_TRUE(gate.hold_bulk_until(t0));
  EXPECT_EQ(*gate.hold_bulk_until(t0), t0 + std::chrono::milliseconds(50));
  gate.stream_started();
  EXPECT_EQ(wakes, 1);
  EXPECT_FALSE(gate.hold_bulk_until(t0));
  EXPECT_EQ(gate.starting(), 0);
}

TEST(FirstChunkGate, ABurstIsHeldFromItsFirstRequestAndWokenOnceAtItsEnd) {
  FirstChunkGate gate(std::chrono::milliseconds(50));
  int wakes = 0;
  gate.add_waker([&] { ++wakes; });
  const auto t0 = GateClock::now();
  gate.stream_starting(t0);
  gate.stream_starting(t0 + std::chrono::milliseconds(30));  // does not extend the hold
  EXPECT_EQ(*gate.hold_bulk_until(t0 + std::chrono::milliseconds(40)),
            t0 + std::chrono::milliseconds(50));
  gate.stream_started();
  EXPECT_EQ(wakes, 0);  // one still starting
  EXPECT_TRUE(gate.hold_bulk_until(t0 + std::chrono::milliseconds(40)));
  gate.stream_started();
  EXPECT_EQ(wakes, 1);
}

TEST(FirstChunkGate, NewRequestsCannotStarveBulkPastTheBound) {
  FirstChunkGate gate(std::chrono::milliseconds(50));
  const auto t0 = GateClock::now();
  gate.stream_starting(t0);
  // Requests keep arriving, the count never drops to zero: bulk goes anyway.
  for (int i = 1; i <= 10; ++i) gate.stream_starting(t0 + std::chrono::milliseconds(10 * i));
  EXPECT_TRUE(gate.hold_bulk_until(t0 + std::chrono::milliseconds(49)));
  EXPECT_FALSE(gate.hold_bulk_until(t0 + std::chrono::milliseconds(50)));
  EXPECT_FALSE(gate.hold_bulk_until(t0 + std::chrono::milliseconds(500)));
  // Once the burst is over, the next one gets a fresh bound.
  for (int i = 0; i <= 10; ++i) gate.stream_started();
  const auto t1 = t0 + std::chrono::seconds(1);
  gate.stream_starting(t1);
  EXPECT_EQ(*gate.hold_bulk_until(t1), t1 + std::chrono::milliseconds(50));
}

TEST(FirstChunkGate, ZeroHoldNeverHolds) {
  FirstChunkGate gate(GateClock::duration::zero());
  const auto t0 = GateClock::now();
  gate.stream_starting(t0);
  EXPECT_FALSE(gate.hold_bulk_until(t0));
  EXPECT_EQ(gate.starting(), 1);  // still counted: bulk steps back once per chunk
}

TEST(FirstChunkGate, StoppedWakersAreNotCalled) {
  FirstChunkGate gate(std::chrono::milliseconds(50));
  int wakes = 0;
  gate.add_waker([&] { ++wakes; });
  gate.stream_starting(GateClock::now());
  gate.stop_waking();
  gate.stream_started();
  EXPECT_EQ(wakes, 0);
  EXPECT_EQ(gate.starting(), 0);
}

// ------------------------------------------------- through the real server

const ModelsFolder& gate_folder = register_models_folder("ms_gate_");

struct GateModels {
  std::string dir;
  std::vector<uint8_t> big;  // ~8 MB: many bulk chunks after the first
};

const GateModels& gate_models() {
  static const GateModels m = [] {
    GateModels out;
    out.dir = gate_folder.create();
    server::SyntheticStreamOptions big;
    big.records = 200;
    big.payload_bytes = 8 << 20;
    big.seed = 5;
    out.big = server::make_synthetic_hcs(big);
    write_file(out.dir + "/big.hcs", out.big);
    return out;
  }();
  return m;
}

// A server whose bulk hold is far longer than any test: a starting stream
// that never released the gate would show as a stream taking >= 20 s.
bool start_holding_server(ServerProcess& server, const std::string& log_name) {
  return server.start(
      {"--models", gate_models().dir, "--cache", "none", "--threads", "2", "--first-chunk-hold-ms",
       "10000", "--stall-timeout-ms", "1500", "--handshake-timeout-ms", "2000"},
      gate_models().dir + "/" + log_name + ".log");
}

// Streams `big` to the end; the seconds it took (byte-exact or a failure).
double timed_full_stream(uint16_t port) {
  TestClient c = greeted_client(port);
  const auto start = Clock::now();
  c.stream("big");
  const StreamResult r = read_stream(c, 30000ms);
  EXPECT_TRUE(r.ok) << r.problem;
  EXPECT_TRUE(r.bytes == gate_models().big);
  return std::chrono::duration<double>(Clock::now() - start).count();
}

TEST(FirstChunkHold, EveryWayAStartingStreamEndsReleasesTheHold) {
  ServerProcess server;
  ASSERT_TRUE(start_holding_server(server, "gate_release")) << server.log();
  const uint16_t port = server.port();
  {
    // Requests, then leaves before reading anything.
    TestClient c = greeted_client(port);
    c.stream("big");
  }
  {
    // Two requests back to back: the first is replaced before its first chunk.
    TestClient c = greeted_client(port);
    c.stream("big");
    c.stream("big");
    const StreamResult first = read_stream(c, 30000ms);
    EXPECT_TRUE(first.ok) << first.problem;
    EXPECT_EQ(first.end.reason(), v1::StreamEnd::CANCELLED);
    const StreamResult second = read_stream(c, 30000ms);
    EXPECT_TRUE(second.ok) << second.problem;
    EXPECT_TRUE(second.bytes == gate_models().big);
  }
  {
    // Cancelled right after the request.
    TestClient c = greeted_client(port);
    c.stream("big");
    c.cancel();
    const StreamResult r = read_stream(c, 30000ms);
    EXPECT_TRUE(r.ok) << r.problem;
  }
  {
    // Resumed past the end: a header and an end, no chunk at all.
    TestClient c = greeted_client(port);
    v1::StreamRequest request;
    request.set_model("big");
    request.set_resume_offset(uint64_t(1) << 40);
    c.stream(request);
    const StreamResult r = read_stream(c, 30000ms);
    EXPECT_TRUE(r.ok) << r.problem;
    EXPECT_TRUE(r.chunks.empty());
  }
  {
    // Unknown model: an error, never a starting stream.
    TestClient c = greeted_client(port);
    c.stream("nope");
    v1::ServerMessage m;
    ASSERT_EQ(c.read(m), ReadEnd::kMessage);
    EXPECT_TRUE(m.has_error());
  }
  // Nothing is starting any more: a fresh stream's bulk is not held. Loopback
  // moves 8 MB in well under a second; a leaked hold would take 10 s.
  EXPECT_LT(timed_full_stream(port), 5.0);
}

TEST(FirstChunkHold, AStreamStuckBehindAStalledWriteHoldsBulkOnlyUntilItsSessionEnds) {
  ServerProcess server;
  ASSERT_TRUE(start_holding_server(server, "gate_stall")) << server.log();
  const uint16_t port = server.port();
  // A client that requests, stops reading (a tiny receive buffer fills), and
  // requests again: its second stream waits behind a write that never ends,
  // so it counts as starting until the stall timeout (1.5 s) closes it.
  TestClient stuck;
  ASSERT_TRUE(stuck.connect(port, 4096));
  ASSERT_TRUE(stuck.hello());
  stuck.stream("big");
  std::this_thread::sleep_for(300ms);
  stuck.stream("big");
  std::this_thread::sleep_for(100ms);
  // Meanwhile another client streams: its first chunk is never held, its
  // bulk only until the stuck session is closed, far below the 10 s hold.
  TestClient c = greeted_client(port);
  const auto start = Clock::now();
  c.stream("big");
  v1::ServerMessage m;
  double first_chunk_s = -1;
  while (c.read(m, 20000ms) == ReadEnd::kMessage && !m.has_end() && !m.has_error()) {
    if (m.has_chunk() && first_chunk_s < 0) {
      first_chunk_s = std::chrono::duration<double>(Clock::now() - start).count();
    }
  }
  const double total_s = std::chrono::duration<double>(Clock::now() - start).count();
  ASSERT_TRUE(m.has_end()) << m.DebugString();
  EXPECT_GE(first_chunk_s, 0.0);
  EXPECT_LT(first_chunk_s, 1.0);
  EXPECT_LT(total_s, 6.0);
}

}  // namespace
}  // namespace meshstream::nettest
