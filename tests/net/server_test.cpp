// Integration tests: the real meshstream-server binary on loopback, real
// sockets, synthetic .hcs models (valid containers with CRCs; the server
// only reads the index). Each test says which contract it checks
// (proto/meshstream.proto, docs/design.md).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>

#include "common/codec/container.h"
#include "server/synthetic_stream.h"
#include "tests/net/greeted_client.h"
#include "tests/net/net_harness.h"

namespace meshstream::nettest {
namespace {

namespace fs = std::filesystem;

const ModelsFolder& models_folder = register_models_folder("ms_net_");

struct Models {
  std::string dir;
  std::vector<uint8_t> small;  // ~200 KB, 60 records, some larger than a chunk
  std::vector<uint8_t> big;    // ~24 MB, for slow readers and cancel
};

// One temporary folder of models for the whole suite.
const Models& models() {
  static const Models m = [] {
    Models out;
    out.dir = models_folder.create();
    server::SyntheticStreamOptions small;
    small.records = 60;
    small.vertices = 20000;
    small.base_bytes = 70000;  // larger than the 64 KiB default chunk
    small.payload_bytes = 150000;
    out.small = server::make_synthetic_hcs(small);
    server::SyntheticStreamOptions big;
    big.records = 400;
    big.payload_bytes = 24 << 20;
    big.seed = 2;
    out.big = server::make_synthetic_hcs(big);
    write_file(out.dir + "/small.hcs", out.small);
    write_file(out.dir + "/big.hcs", out.big);
    // Not a valid stream: reported and skipped, the rest still served.
    write_file(out.dir + "/broken.hcs", std::vector<uint8_t>{'M', 'H', 'C', 'S', 1, 0});
    return out;
  }();
  return m;
}

StreamIndex index_of(const std::vector<uint8_t>& bytes) { return *read_stream_index(bytes); }

std::vector<std::string> base_args(const std::vector<std::string>& extra = {}) {
  std::vector<std::string> args{"--models",
                                models().dir,
                                "--cache",
                                "none",
                                "--threads",
                                "2",
                                "--handshake-timeout-ms",
                                "700",
                                "--idle-timeout-ms",
                                "3000",
                                "--stall-timeout-ms",
                                "1500"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

std::string log_path(const std::string& name) { return models().dir + "/" + name + ".log"; }

// The server most tests share.
class NetTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    server_ = new ServerProcess();
    ASSERT_TRUE(server_->start(base_args(), log_path("shared"))) << server_->log();
  }
  static void TearDownTestSuite() {
    delete server_;
    server_ = nullptr;
  }
  void SetUp() override { ASSERT_NE(server_, nullptr); }

  // A connected client past the handshake.
  static TestClient connected() { return greeted_client(server_->port()); }

  static ServerProcess* server_;
};
ServerProcess* NetTest::server_ = nullptr;

TEST_F(NetTest, HelloAnnouncesVersionAndLimits) {
  TestClient c;
  ASSERT_TRUE(c.connect(server_->port()));
  ASSERT_TRUE(c.hello());
  v1::ServerMessage m;
  ASSERT_EQ(c.read(m), ReadEnd::kMessage);
  ASSERT_TRUE(m.has_hello());
  EXPECT_EQ(m.hello().protocol_version(), proto::kProtocolVersion);
  EXPECT_EQ(m.hello().max_client_frame_bytes(), proto::kDefaultMaxClientFrameBytes);
  EXPECT_EQ(m.hello().max_server_frame_bytes(), proto::kMaxServerFrameBytes);
}

TEST_F(NetTest, ListShowsEveryValidModelWithItsFacts) {
  TestClient c = connected();
  ASSERT_TRUE(c.list());
  v1::ServerMessage m;
  ASSERT_EQ(c.read(m), ReadEnd::kMessage);
  ASSERT_TRUE(m.has_model_list()) << m.DebugString();
  const auto& list = m.model_list().models();
  // broken.hcs is listed as failed, with the reason naming it.
  ASSERT_EQ(list.size(), 3) << m.DebugString();
  EXPECT_EQ(list[0].name(), "big");
  EXPECT_EQ(list[0].state(), v1::ModelInfo::READY);
  EXPECT_EQ(list[1].name(), "broken");
  EXPECT_EQ(list[1].state(), v1::ModelInfo::FAILED);
  EXPECT_NE(list[1].reason().find(models().dir + "/broken.hcs"), std::string::npos)
      << list[1].reason();
  EXPECT_EQ(list[1].stream_bytes(), 0u);
  EXPECT_EQ(list[2].name(), "small");
  EXPECT_EQ(list[2].state(), v1::ModelInfo::READY);
  const StreamIndex small = index_of(models().small);
  EXPECT_EQ(list[2].stream_bytes(), models().small.size());
  EXPECT_EQ(list[2].records(), small.records.size());
  EXPECT_EQ(list[2].vertices(), small.header.vertex_count);
  EXPECT_EQ(list[2].faces(), small.header.face_count);
  EXPECT_EQ(list[2].source(), "hcs");
  EXPECT_NE(server_->log().find("broken.hcs"), std::string::npos);
}

TEST_F(NetTest, FullStreamIsByteIdenticalToTheFile) {
  TestClient c = connected();
  ASSERT_TRUE(c.stream("small"));
  const StreamResult r = read_stream(c);
  ASSERT_TRUE(r.ok) << r.problem;
  EXPECT_EQ(r.bytes, models().small);
  EXPECT_EQ(r.end.reason(), v1::StreamEnd::COMPLETE);
  EXPECT_EQ(r.end.bytes_sent(), models().small.size());
  EXPECT_EQ(r.end.end_offset(), models().small.size());

  // The header repeats the container's index.
  const StreamIndex index = index_of(models().small);
  EXPECT_EQ(r.header.total_bytes(), models().small.size());
  EXPECT_EQ(r.header.payload_offset(), index.payload_offset);
  EXPECT_EQ(r.header.container_version(), index.version);
  EXPECT_EQ(r.header.end_record(), index.records.size());
  ASSERT_EQ(r.header.records().sizes_size(), int(index.records.size()));
  for (size_t i = 0; i < index.records.size(); ++i) {
    EXPECT_EQ(r.header.records().sizes(int(i)), index.records[i].size);
    EXPECT_EQ(r.header.records().vertices(int(i)), index.records[i].vertices);
    EXPECT_EQ(r.header.records().crc32(int(i)), index.records[i].crc32);
  }
  // Chunks: within the limit, records_complete right, cut on boundaries
  // except inside records larger than a chunk.
  EXPECT_EQ(r.end.records_complete(), index.records.size());
  for (size_t k = 0; k < r.chunks.size(); ++k) {
    const v1::Chunk& chunk = r.chunks[k];
    // Slow start: 8 KiB, doubling per chunk, up to max_chunk_bytes.
    const size_t limit =
        std::min<size_t>(r.header.max_chunk_bytes(), size_t(8192) << std::min<size_t>(k, 20));
    EXPECT_LE(chunk.data().size(), limit) << "chunk " << k;
    const uint64_t end = chunk.offset() + chunk.data().size();
    uint32_t complete = 0;
    bool boundary = end == index.payload_offset;
    for (const RecordEntry& rec : index.records) {
      if (rec.offset + rec.size <= end) ++complete;
      if (rec.offset + rec.size == end) boundary = true;
    }
    EXPECT_EQ(chunk.records_complete(), complete);
    if (!boundary) {
      const uint64_t unit =
          end < index.payload_offset ? index.payload_offset : index.records[complete].size;
      EXPECT_GT(unit, limit) << "chunk " << k << " splits a record that would fit";
    }
  }
}

TEST_F(NetTest, EveryBudgetKindEndsOnARecordBoundary) {
  const StreamIndex index = index_of(models().small);
  auto boundary_end = [&](uint32_t records) {
    return index.records[records - 1].offset + index.records[records - 1].size;
  };
  TestClient c = connected();
  struct Case {
    v1::Budget budget;
    uint32_t expected_records;
  };
  std::vector<Case> cases;
  {
    v1::Budget b;  // one byte short of record 30's end
    b.set_bytes(boundary_end(31) - 1);
    cases.push_back({b, 30});
  }
  {
    v1::Budget b;
    b.set_vertices(index.records[40].vertices);
    cases.push_back({b, 41});
  }
  {
    v1::Budget b;
    b.set_percent(50);
    uint32_t n = 0;
    while (n < index.records.size() && boundary_end(n + 1) <= models().small.size() / 2) ++n;
    cases.push_back({b, std::max(n, 1u)});
  }
  {
    v1::Budget b;  // below the base mesh: the base mesh still comes whole
    b.set_bytes(5);
    cases.push_back({b, 1});
  }
  for (const Case& k : cases) {
    v1::StreamRequest request;
    request.set_model("small");
    *request.mutable_budget() = k.budget;
    ASSERT_TRUE(c.stream(request));
    const StreamResult r = read_stream(c);
    ASSERT_TRUE(r.ok) << r.problem << " " << k.budget.DebugString();
    const uint64_t end = boundary_end(k.expected_records);
    EXPECT_EQ(r.header.end_record(), k.expected_records) << k.budget.DebugString();
    EXPECT_EQ(r.header.end_offset(), end);
    EXPECT_EQ(r.end.reason(), v1::StreamEnd::BUDGET);
    EXPECT_EQ(r.end.records_complete(), k.expected_records);
    ASSERT_EQ(r.bytes.size(), end);
    EXPECT_TRUE(std::equal(r.bytes.begin(), r.bytes.end(), models().small.begin()));
  }
  // A percent out of range is an error that keeps the connection.
  v1::StreamRequest bad;
  bad.set_model("small");
  bad.mutable_budget()->set_percent(150);
  ASSERT_TRUE(c.stream(bad));
  const StreamResult r = read_stream(c);
  ASSERT_TRUE(r.error.has_value());
  EXPECT_EQ(r.error->code(), v1::Error::INVALID_REQUEST);
  EXPECT_FALSE(r.error->closing());
  ASSERT_TRUE(c.stream("small"));
  EXPECT_TRUE(read_stream(c).ok);
}

TEST_F(NetTest, ResumeGivesPrefixPlusRestEqualToTheFile) {
  const std::vector<uint8_t>& file = models().small;
  const StreamIndex index = index_of(file);
  TestClient c = connected();
  // Take a prefix that ends mid-record, as a dropped connection would.
  for (uint64_t cut : {uint64_t(0), uint64_t(10), index.payload_offset + 3,
                       index.records[25].offset + index.records[25].size / 2,
                       uint64_t(file.size()) - 1, uint64_t(file.size())}) {
    v1::StreamRequest request;
    request.set_model("small");
    request.set_resume_offset(cut);
    ASSERT_TRUE(c.stream(request));
    const StreamResult r = read_stream(c);
    ASSERT_TRUE(r.ok) << r.problem;
    const uint64_t start = r.header.start_offset();
    EXPECT_LE(start, cut);
    // The real start is a boundary: 0 or a record's offset.
    bool aligned = start == 0 || start == file.size();
    for (const RecordEntry& rec : index.records) aligned |= rec.offset == start;
    EXPECT_TRUE(aligned) << start;
    std::vector<uint8_t> joined(file.begin(), file.begin() + std::ptrdiff_t(start));
    joined.insert(joined.end(), r.bytes.begin(), r.bytes.end());
    EXPECT_EQ(joined, file) << "resume at " << cut;
    EXPECT_EQ(r.end.reason(), v1::StreamEnd::COMPLETE);
  }
}

TEST_F(NetTest, CancelStopsTheStreamAndKeepsTheConnection) {
  TestClient c = connected();
  v1::StreamRequest request;
  request.set_model("big");
  request.set_max_chunk_bytes(4096);
  ASSERT_TRUE(c.stream(request));
  v1::ServerMessage m;
  ASSERT_EQ(c.read(m), ReadEnd::kMessage);
  ASSERT_TRUE(m.has_header());
  ASSERT_TRUE(c.cancel());
  uint64_t received = 0;
  while (true) {
    ASSERT_EQ(c.read(m), ReadEnd::kMessage);
    if (m.has_chunk()) {
      received += m.chunk().data().size();
      continue;
    }
    ASSERT_TRUE(m.has_end()) << m.DebugString();
    break;
  }
  EXPECT_EQ(m.end().reason(), v1::StreamEnd::CANCELLED);
  EXPECT_EQ(m.end().bytes_sent(), received);
  EXPECT_LT(received, models().big.size());
  // Same connection still serves.
  ASSERT_TRUE(c.list());
  ASSERT_EQ(c.read(m), ReadEnd::kMessage);
  EXPECT_TRUE(m.has_model_list());
  // A cancel with nothing running is ignored; the next request works.
  ASSERT_TRUE(c.cancel());
  ASSERT_TRUE(c.stream("small"));
  const StreamResult r = read_stream(c);
  ASSERT_TRUE(r.ok) << r.problem;
  EXPECT_EQ(r.bytes, models().small);
}

TEST_F(NetTest, UnknownModelsAreErrorsNeverPaths) {
  TestClient c = connected();
  for (const char* name : {"nope", "../../etc/passwd", "/etc/passwd", "small.hcs", ""}) {
    ASSERT_TRUE(c.stream(name));
    v1::ServerMessage m;
    ASSERT_EQ(c.read(m), ReadEnd::kMessage);
    ASSERT_TRUE(m.has_error()) << name << ": " << m.DebugString();
    EXPECT_EQ(m.error().code(), v1::Error::UNKNOWN_MODEL);
    EXPECT_FALSE(m.error().closing());
  }
  // A model whose file is broken is known, and says why it cannot be served.
  ASSERT_TRUE(c.stream("broken"));
  v1::ServerMessage m;
  ASSERT_EQ(c.read(m), ReadEnd::kMessage);
  ASSERT_TRUE(m.has_error()) << m.DebugString();
  EXPECT_EQ(m.error().code(), v1::Error::MODEL_FAILED);
  EXPECT_FALSE(m.error().closing());
  EXPECT_EQ(m.error().model().state(), v1::ModelInfo::FAILED);
  EXPECT_NE(
      m.error().message().find("model 'broken' cannot be served: " + models().dir + "/broken.hcs"),
      std::string::npos)
      << m.error().message();
  ASSERT_TRUE(c.stream("small"));
  EXPECT_TRUE(read_stream(c).ok);
}

// Issue 21 row 16: the error frame suggests the close names, the server logs
// the request (control bytes escaped, so a client cannot forge log lines).
TEST_F(NetTest, UnknownModelSuggestsCloseNamesAndIsLogged) {
  TestClient c = connected();
  const std::vector<std::pair<std::string, std::string>> cases{
      {"smal", "unknown model 'smal': did you mean 'small'? (see --list)"},
      {"small.hcs", "unknown model 'small.hcs': did you mean 'small'? (see --list)"},
      {"bgi", "unknown model 'bgi': did you mean 'big'? (see --list)"},
      {"teapot", "unknown model 'teapot' (see --list)"},
      {"evil\nname", "unknown model 'evil\\x0aname' (see --list)"}};
  for (const auto& [name, expected] : cases) {
    ASSERT_TRUE(c.stream(name));
    v1::ServerMessage m;
    ASSERT_EQ(c.read(m), ReadEnd::kMessage);
    ASSERT_TRUE(m.has_error()) << m.DebugString();
    EXPECT_EQ(m.error().code(), v1::Error::UNKNOWN_MODEL);
    EXPECT_EQ(m.error().message(), expected);
    EXPECT_FALSE(m.error().closing());
  }
  // The log has each request, on one line.
  const auto deadline = Clock::now() + 2s;
  while (server_->log().find("unknown model 'evil") == std::string::npos &&
         Clock::now() < deadline) {
    std::this_thread::sleep_for(20ms);
  }
  const std::string log = server_->log();
  EXPECT_NE(log.find(": unknown model 'smal': did you mean 'small'? (see --list)"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find(": unknown model 'evil\\x0aname' (see --list)"), std::string::npos) << log;
  EXPECT_EQ(log.find("evil\nname"), std::string::npos) << log;
}

// Sends `bytes` on a fresh connection (after Hello when `after_hello`) and
// expects one Error frame with `code`, then the close.
void expect_error_and_close(uint16_t port, const std::vector<uint8_t>& bytes, bool after_hello,
                            v1::Error::Code code) {
  TestClient c;
  ASSERT_TRUE(c.connect(port));
  v1::ServerMessage m;
  if (after_hello) {
    ASSERT_TRUE(c.hello());
    ASSERT_EQ(c.read(m), ReadEnd::kMessage);
  }
  ASSERT_TRUE(c.send_raw(bytes));
  ASSERT_EQ(c.read(m), ReadEnd::kMessage);
  ASSERT_TRUE(m.has_error()) << m.DebugString();
  EXPECT_EQ(m.error().code(), code) << m.error().message();
  EXPECT_TRUE(m.error().closing());
  EXPECT_TRUE(c.wait_closed(3000ms));
}

TEST_F(NetTest, GarbageBytesGetAnErrorAndAClose) {
  // A plausible length, then bytes that are no ClientMessage.
  std::vector<uint8_t> garbage{12};
  for (int i = 0; i < 12; ++i) garbage.push_back(0xff);
  expect_error_and_close(server_->port(), garbage, true, v1::Error::MALFORMED_FRAME);
  expect_error_and_close(server_->port(), garbage, false, v1::Error::MALFORMED_FRAME);
  // Lots of random garbage: whatever it parses as, it is an error and a close.
  std::vector<uint8_t> noise(100000);
  uint32_t x = 12345;
  for (auto& b : noise) b = uint8_t((x = x * 1103515245 + 12345) >> 16);
  TestClient c;
  ASSERT_TRUE(c.connect(server_->port()));
  c.send_raw(noise);  // may fail half-way once the server closes
  std::vector<v1::ServerMessage> seen;
  EXPECT_TRUE(c.wait_closed(3000ms, &seen));
  ASSERT_FALSE(seen.empty());
  EXPECT_TRUE(seen.back().has_error());
  // Nobody else noticed.
  TestClient other = connected();
  ASSERT_TRUE(other.stream("small"));
  EXPECT_EQ(read_stream(other).bytes, models().small);
}

TEST_F(NetTest, TwoGibLengthPrefixIsRefusedWithoutAllocating) {
  const long before = server_->status_kib("RssAnon");
  std::vector<uint8_t> prefix;
  proto::append_varint(prefix, uint64_t(2) << 30);
  expect_error_and_close(server_->port(), prefix, true, v1::Error::FRAME_TOO_LARGE);
  // Just over the configured limit, too.
  std::vector<uint8_t> over;
  proto::append_varint(over, proto::kDefaultMaxClientFrameBytes + 1);
  expect_error_and_close(server_->port(), over, false, v1::Error::FRAME_TOO_LARGE);
  const long after = server_->status_kib("RssAnon");
  EXPECT_LT(after - before, 16 * 1024)
      << "RssAnon grew from " << before << " to " << after << " KiB";
}

TEST_F(NetTest, WrongProtocolVersionIsRefused) {
  for (uint32_t version : {0u, 2u, 999u}) {
    v1::ClientMessage hello;
    hello.mutable_hello()->set_protocol_version(version);
    expect_error_and_close(server_->port(), proto::encode_frame(hello), false,
                           v1::Error::VERSION_MISMATCH);
  }
  // A request before Hello is a protocol violation.
  v1::ClientMessage list;
  list.mutable_list_models();
  expect_error_and_close(server_->port(), proto::encode_frame(list), false,
                         v1::Error::PROTOCOL_VIOLATION);
}

TEST_F(NetTest, SilentClientTimesOut) {
  TestClient c;
  ASSERT_TRUE(c.connect(server_->port()));
  const auto start = Clock::now();
  v1::ServerMessage m;
  ASSERT_EQ(c.read(m, 5000ms), ReadEnd::kMessage);
  const auto waited = Clock::now() - start;
  ASSERT_TRUE(m.has_error());
  EXPECT_EQ(m.error().code(), v1::Error::TIMEOUT);
  EXPECT_TRUE(m.error().closing());
  EXPECT_GE(waited, 600ms);  // the handshake timeout is 700 ms
  EXPECT_TRUE(c.wait_closed(3000ms));
}

TEST_F(NetTest, IdleClientTimesOutAfterHello) {
  TestClient c = connected();
  v1::ServerMessage m;
  ASSERT_EQ(c.read(m, 8000ms), ReadEnd::kMessage);
  ASSERT_TRUE(m.has_error());
  EXPECT_EQ(m.error().code(), v1::Error::TIMEOUT);
  EXPECT_TRUE(c.wait_closed(3000ms));
}

TEST_F(NetTest, ClientsThatStopReadingCostBoundedMemory) {
  const long before = server_->status_kib("RssAnon");
  // 20 clients ask for 24 MB each and never read: without one-write-in-flight
  // that would be ~480 MB buffered.
  std::vector<TestClient> clients;
  for (int i = 0; i < 20; ++i) {
    TestClient c;
    ASSERT_TRUE(c.connect(server_->port(), 4096));
    ASSERT_TRUE(c.hello());
    ASSERT_TRUE(c.stream("big"));
    clients.push_back(std::move(c));
  }
  std::this_thread::sleep_for(800ms);
  const long during = server_->status_kib("RssAnon");
  EXPECT_LT(during - before, 8 * 1024) << "RssAnon " << before << " -> " << during << " KiB";
  // Meanwhile everyone else is served.
  TestClient other = connected();
  ASSERT_TRUE(other.stream("small"));
  EXPECT_EQ(read_stream(other).bytes, models().small);
  // The stall timeout (1.5 s) closes them.
  std::this_thread::sleep_for(2500ms);
  const std::string log = server_->log();
  size_t stalled = 0;
  for (size_t at = log.find("stalled"); at != std::string::npos; at = log.find("stalled", at + 1)) {
    ++stalled;
  }
  EXPECT_GE(stalled, 20u) << log.substr(log.size() > 4000 ? log.size() - 4000 : 0);
}

TEST_F(NetTest, TwoHundredConcurrentClientsAllByteExact) {
  constexpr int kClients = 200;
  std::atomic<int> exact{0};
  std::vector<std::string> problems(kClients);
  std::vector<std::thread> threads;
  for (int i = 0; i < kClients; ++i) {
    threads.emplace_back([&, i] {
      TestClient c;
      if (!c.connect(server_->port()) || !c.hello()) {
        problems[i] = "connect";
        return;
      }
      v1::ServerMessage m;
      if (c.read(m, 20000ms) != ReadEnd::kMessage || !m.has_hello()) {
        problems[i] = "hello: " + m.DebugString();
        return;
      }
      c.stream("small");
      const StreamResult r = read_stream(c, 40000ms);
      if (r.ok && r.bytes == models().small) {
        ++exact;
      } else {
        problems[i] = r.problem;
      }
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(exact.load(), kClients);
  for (int i = 0; i < kClients; ++i) {
    if (!problems[i].empty()) ADD_FAILURE() << "client " << i << ": " << problems[i];
  }
}

TEST_F(NetTest, CapturedFrameDecodesWithRealProtoc) {
  // Raw frames straight off the socket, no re-serialization.
  TestClient c;
  ASSERT_TRUE(c.connect(server_->port()));
  ASSERT_TRUE(c.hello());
  ASSERT_TRUE(c.list());
  v1::StreamRequest request;
  request.set_model("small");
  request.mutable_budget()->set_vertices(0);
  ASSERT_TRUE(c.stream(request));
  proto::FrameSplitter splitter(proto::kMaxServerFrameBytes);
  std::vector<std::vector<uint8_t>> frames;
  const auto deadline = Clock::now() + 5s;
  while (frames.size() < 4 && Clock::now() < deadline) {
    pollfd p{c.fd(), POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    uint8_t buffer[65536];
    const ssize_t n = ::recv(c.fd(), buffer, sizeof buffer, 0);
    ASSERT_GT(n, 0);
    splitter.feed(std::span<const uint8_t>(buffer, size_t(n)));
    while (true) {
      auto frame = splitter.next();
      ASSERT_TRUE(frame.has_value());
      if (!*frame) break;
      frames.emplace_back((*frame)->begin(), (*frame)->end());
    }
  }
  ASSERT_GE(frames.size(), 4u);  // hello, list, header, first chunk
  const std::string dir = models().dir;
  auto decode = [&](const std::vector<uint8_t>& frame, const std::string& name) {
    write_file(dir + "/" + name + ".bin", frame);
    const std::string cmd = std::string(MESHSTREAM_PROTOC) + " -I " + MESHSTREAM_SOURCE_DIR +
                            " --decode meshstream.v1.ServerMessage proto/meshstream.proto < " +
                            dir + "/" + name + ".bin > " + dir + "/" + name + ".txt 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::ifstream in(dir + "/" + name + ".txt");
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  const std::string list = decode(frames[1], "list");
  EXPECT_NE(list.find("model_list {"), std::string::npos) << list;
  EXPECT_NE(list.find("name: \"small\""), std::string::npos) << list;
  EXPECT_NE(list.find("stream_bytes: " + std::to_string(models().small.size())), std::string::npos)
      << list;
  const std::string header = decode(frames[2], "header");
  EXPECT_NE(header.find("total_bytes: " + std::to_string(models().small.size())), std::string::npos)
      << header.substr(0, 2000);
  // The chunk frame is written by the zero-copy path.
  const std::string chunk = decode(frames[3], "chunk");
  EXPECT_NE(chunk.find("chunk {"), std::string::npos) << chunk.substr(0, 300);
  EXPECT_NE(chunk.find("data: \"MHCS"), std::string::npos) << chunk.substr(0, 300);
}

// --- tests with servers of their own -------------------------------------

TEST(NetServer, MaxConnectionsTurnsAwayExtraClientsWithBusy) {
  ServerProcess server;
  ASSERT_TRUE(server.start(base_args({"--max-connections", "2"}), log_path("busy")))
      << server.log();
  std::vector<TestClient> kept;
  for (int i = 0; i < 2; ++i) {
    TestClient c;
    ASSERT_TRUE(c.connect(server.port()));
    ASSERT_TRUE(c.hello());
    v1::ServerMessage m;
    ASSERT_EQ(c.read(m), ReadEnd::kMessage);
    ASSERT_TRUE(m.has_hello());
    kept.push_back(std::move(c));
  }
  TestClient extra;
  ASSERT_TRUE(extra.connect(server.port()));
  v1::ServerMessage m;
  ASSERT_EQ(extra.read(m), ReadEnd::kMessage);
  ASSERT_TRUE(m.has_error());
  EXPECT_EQ(m.error().code(), v1::Error::BUSY);
  EXPECT_TRUE(extra.wait_closed(3000ms));
  // A slot frees up when a client leaves.
  kept[0].close();
  bool served = false;
  for (int attempt = 0; attempt < 50 && !served; ++attempt) {
    TestClient again;
    ASSERT_TRUE(again.connect(server.port()));
    ASSERT_TRUE(again.hello());
    served = again.read(m) == ReadEnd::kMessage && m.has_hello();
    if (!served) std::this_thread::sleep_for(20ms);
  }
  EXPECT_TRUE(served);
}

TEST(NetServer, RatePacingMakesArrivalProgressive) {
  ServerProcess server;
  ASSERT_TRUE(server.start(base_args({"--rate", "400000"}), log_path("rate"))) << server.log();
  TestClient c;
  ASSERT_TRUE(c.connect(server.port()));
  ASSERT_TRUE(c.hello());
  v1::ServerMessage m;
  ASSERT_EQ(c.read(m), ReadEnd::kMessage);
  const auto start = Clock::now();
  ASSERT_TRUE(c.stream("small"));  // ~225 KB at 400 KB/s: ~0.55 s
  const StreamResult r = read_stream(c);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  ASSERT_TRUE(r.ok) << r.problem;
  EXPECT_EQ(r.bytes, models().small);
  const double expected = double(models().small.size()) / 400000.0;
  EXPECT_GT(seconds, expected * 0.7) << "arrived too fast";
  EXPECT_LT(seconds, expected * 2.0 + 0.5) << "arrived too slowly";
  EXPECT_GT(r.chunks.size(), 10u);  // many small paced chunks
}

// --rate stands for a slow link: the stream header (here the arrays form of
// the record index, about 12 bytes a record) is paced with the first chunk,
// not sent for free. The bucket starts with one chunk's worth (the header's
// max_chunk_bytes); the rest of header + first chunk waits for the rate.
TEST(NetServer, RatePacingChargesTheStreamHeader) {
  constexpr double kRate = 4000;
  ServerProcess server;
  ASSERT_TRUE(server.start(base_args({"--rate", "4000"}), log_path("rate_header"))) << server.log();
  TestClient c = greeted_client(server.port());
  const auto start = Clock::now();
  ASSERT_TRUE(c.stream("small"));
  v1::ServerMessage header, chunk;
  ASSERT_EQ(c.read(header), ReadEnd::kMessage);
  ASSERT_TRUE(header.has_header());
  ASSERT_EQ(c.read(chunk), ReadEnd::kMessage);
  ASSERT_TRUE(chunk.has_chunk());
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  const double paced = double(header.ByteSizeLong()) + double(chunk.chunk().data().size()) -
                       double(header.header().max_chunk_bytes());
  // Without the header charged this would arrive after (first chunk -
  // burst) / rate: the bound below tells the two apart.
  const double header_bytes = double(header.ByteSizeLong());
  ASSERT_LT(paced - header_bytes, 0.8 * paced)
      << "test setup: the header must be a fair share of the paced bytes";
  EXPECT_GT(seconds, 0.8 * paced / kRate)
      << "header " << header_bytes << " B and first chunk " << chunk.chunk().data().size()
      << " B arrived faster than the rate";
}

TEST(NetServer, SigtermMidStreamShutsDownCleanly) {
  ServerProcess server;
  ASSERT_TRUE(server.start(base_args({"--rate", "1000000"}), log_path("sigterm"))) << server.log();
  TestClient c;
  ASSERT_TRUE(c.connect(server.port()));
  ASSERT_TRUE(c.hello());
  v1::ServerMessage m;
  ASSERT_EQ(c.read(m), ReadEnd::kMessage);
  ASSERT_TRUE(c.stream("big"));  // 24 s at 1 MB/s
  ASSERT_EQ(c.read(m), ReadEnd::kMessage);
  ASSERT_TRUE(m.has_header());
  ASSERT_EQ(c.read(m), ReadEnd::kMessage);
  ASSERT_TRUE(m.has_chunk());
  server.signal(SIGTERM);
  std::vector<v1::ServerMessage> seen;
  EXPECT_TRUE(c.wait_closed(5000ms, &seen));
  ASSERT_FALSE(seen.empty());
  EXPECT_TRUE(seen.back().has_error());
  EXPECT_EQ(seen.back().error().code(), v1::Error::SHUTTING_DOWN);
  const auto status = server.wait_exit(5000ms);
  ASSERT_TRUE(status.has_value()) << "server did not exit";
  EXPECT_EQ(*status, 0) << server.log();
  // New connections are refused once it is gone.
  TestClient late;
  EXPECT_FALSE(late.connect(server.port()));
}

TEST(NetServer, SigintWithNoClientsExitsZero) {
  ServerProcess server;
  ASSERT_TRUE(server.start(base_args(), log_path("sigint"))) << server.log();
  server.signal(SIGINT);
  const auto status = server.wait_exit(5000ms);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(*status, 0);
}

TEST(NetServer, UsageErrorsExitTwoWithOneLine) {
  // (--models naming no folder is bad input, exit 1: startup_test.cpp.)
  for (const std::string args :
       {"", "--models . --listen nope", "--models . --max-connections 0", "--bogus"}) {
    const std::string cmd =
        server_binary() + " " + args + " > /dev/null 2> " + models().dir + "/usage.txt";
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 2) << args;
    const std::vector<uint8_t> text = read_file(models().dir + "/usage.txt");
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << args;
  }
  const std::string help = server_binary() + " --help > /dev/null";
  EXPECT_EQ(std::system(help.c_str()), 0);
}

TEST(NetServer, PortInUseExitsOne) {
  ServerProcess first;
  ASSERT_TRUE(first.start(base_args(), log_path("port1"))) << first.log();
  const std::string cmd = server_binary() + " --models " + models().dir +
                          " --cache none --listen 127.0.0.1:" + std::to_string(first.port()) +
                          " > /dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
}

}  // namespace
}  // namespace meshstream::nettest
