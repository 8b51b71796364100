// Ranged requests (StreamRequest.records, proto/meshstream.proto) against the
// real meshstream-server on loopback: the server sends exactly the records
// asked, in the order asked, refuses bad lists with an error naming the range
// while the connection and every other client go on, and trusts no order:
// records that arrive before their needs are the client decoder's to refuse.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "common/codec/container.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/procedural.h"
#include "server/synthetic_stream.h"
#include "tests/net/greeted_client.h"
#include "tests/net/net_harness.h"

namespace meshstream::nettest {
namespace {

namespace fs = std::filesystem;

const ModelsFolder& models_folder = register_models_folder("ms_ranged_");

struct Models {
  std::string dir;
  std::vector<uint8_t> synthetic;  // 60 records, some larger than a chunk
  std::vector<uint8_t> sphere;     // a real stream that decodes
};

const Models& models() {
  static const Models m = [] {
    Models out;
    out.dir = models_folder.create();
    server::SyntheticStreamOptions o;
    o.records = 60;
    o.vertices = 20000;
    o.base_bytes = 70000;
    o.payload_bytes = 150000;
    out.synthetic = server::make_synthetic_hcs(o);
    Mesh sphere = make_icosphere(4);
    for (Vec3f& p : sphere.positions) p = p * (1.0f + 0.2f * std::sin(5 * p.x) * std::cos(4 * p.y));
    out.sphere = *encode_hcs(sphere);
    write_file(out.dir + "/synthetic.hcs", out.synthetic);
    write_file(out.dir + "/sphere.hcs", out.sphere);
    return out;
  }();
  return m;
}

v1::StreamRequest ranged(const std::string& model,
                         const std::vector<std::pair<uint32_t, uint32_t>>& ranges) {
  v1::StreamRequest request;
  request.set_model(model);
  v1::RecordSelection* selection = request.mutable_records();
  for (const auto& [first, end] : ranges) {
    v1::RecordRange* range = selection->add_ranges();
    range->set_first(first);
    range->set_end(end);
  }
  return request;
}

// The record whose bytes hold stream offset `at`.
uint32_t record_at(const StreamIndex& index, uint64_t at) {
  auto it =
      std::upper_bound(index.records.begin(), index.records.end(), at,
                       [](uint64_t o, const RecordEntry& r) { return o < r.offset + r.size; });
  return static_cast<uint32_t>(it - index.records.begin());
}

class RangedTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    server_ = new ServerProcess();
    ASSERT_TRUE(server_->start({"--models", models().dir, "--cache", "none", "--threads", "2"},
                               models().dir + "/server.log"))
        << server_->log();
  }
  static void TearDownTestSuite() {
    delete server_;
    server_ = nullptr;
  }
  void SetUp() override { ASSERT_NE(server_, nullptr); }
  static TestClient connected() { return greeted_client(server_->port()); }
  static ServerProcess* server_;
};
ServerProcess* RangedTest::server_ = nullptr;

TEST_F(RangedTest, SendsExactlyTheRecordsAskedInTheOrderAsked) {
  const std::vector<uint8_t>& file = models().synthetic;
  const StreamIndex index = *read_stream_index(file);
  const std::vector<std::pair<uint32_t, uint32_t>> ranges{
      {40, 60}, {0, 1}, {7, 9}, {1, 2}, {20, 30}};
  TestClient c = connected();
  v1::StreamRequest request = ranged("synthetic", ranges);
  request.set_max_chunk_bytes(4096);  // several chunks per range, records split
  ASSERT_TRUE(c.stream(request));
  const StreamResult r = read_stream(c);
  ASSERT_TRUE(r.ok) << r.problem;
  EXPECT_TRUE(r.header.ranged());
  EXPECT_EQ(r.header.first_record(), 40u);
  EXPECT_EQ(r.header.end_record(), 30u);
  EXPECT_EQ(r.header.records().sizes_size(), int(index.records.size()));

  // Walk the chunks range by range: each range's chunks are contiguous from
  // its first record's offset and hold exactly the file's bytes there.
  size_t chunk = 0;
  uint64_t expected_bytes = 0;
  uint32_t records_sent = 0;
  for (const auto& [first, end] : ranges) {
    const uint64_t start = index.records[first].offset;
    const uint64_t stop = index.records[end - 1].offset + index.records[end - 1].size;
    expected_bytes += stop - start;
    for (uint64_t at = start; at < stop; ++chunk) {
      ASSERT_LT(chunk, r.chunks.size()) << "range [" << first << ", " << end << ") cut short";
      const v1::Chunk& piece = r.chunks[chunk];
      ASSERT_EQ(piece.offset(), at) << "chunk " << chunk;
      ASSERT_LE(at + piece.data().size(), stop) << "chunk " << chunk << " spills out of its range";
      const std::vector<uint8_t> data(piece.data().begin(), piece.data().end());
      EXPECT_TRUE(std::equal(data.begin(), data.end(), file.begin() + std::ptrdiff_t(at)))
          << "chunk " << chunk;
      at += piece.data().size();
      // records_complete counts the requested records sent whole, in order.
      uint32_t whole = 0;
      for (uint32_t rec = first; rec < end; ++rec) {
        if (index.records[rec].offset + index.records[rec].size <= at) ++whole;
      }
      EXPECT_EQ(piece.records_complete(), records_sent + whole) << "chunk " << chunk;
    }
    records_sent += end - first;
  }
  EXPECT_EQ(chunk, r.chunks.size()) << "chunks beyond the ranges asked";
  EXPECT_EQ(r.header.ranged_bytes(), expected_bytes);
  EXPECT_EQ(r.end.reason(), v1::StreamEnd::RECORDS_SENT);
  EXPECT_EQ(r.end.bytes_sent(), expected_bytes);
  EXPECT_EQ(r.end.records_complete(), records_sent);

  // An ordinary request on the same connection is the file, as before.
  ASSERT_TRUE(c.stream("synthetic"));
  const StreamResult whole = read_stream(c);
  ASSERT_TRUE(whole.ok) << whole.problem;
  EXPECT_EQ(whole.bytes, file);
  EXPECT_FALSE(whole.header.ranged());
}

TEST_F(RangedTest, BadListsAreRefusedNamingTheRangeAndEveryoneGoesOn) {
  // Another client streams the whole file meanwhile, unaffected.
  std::vector<uint8_t> other_bytes;
  std::string other_problem;
  std::thread other([&] {
    TestClient o = connected();
    v1::StreamRequest request;
    request.set_model("synthetic");
    request.set_max_chunk_bytes(1024);
    o.stream(request);
    const StreamResult r = read_stream(o);
    other_bytes = r.bytes;
    other_problem = r.problem;
  });

  TestClient c = connected();
  struct Case {
    v1::StreamRequest request;
    std::string message;
  };
  std::vector<Case> cases{
      {ranged("synthetic", {}), "records: the list of ranges is empty"},
      {ranged("synthetic", {{3, 3}}), "records.ranges[0] [3, 3) is empty"},
      {ranged("synthetic", {{0, 1}, {9, 4}}),
       "records.ranges[1] [9, 4) is reversed (end before first)"},
      {ranged("synthetic", {{55, 61}}),
       "records.ranges[0] [55, 61) is out of bounds: the stream has 60 records, 0 to 59"},
      {ranged("synthetic", {{4000000000u, 4000000001u}}),
       "records.ranges[0] [4000000000, 4000000001) is out of bounds: the stream has 60 records, "
       "0 to 59"},
      {ranged("synthetic", {{2, 6}, {5, 8}}),
       "records.ranges[0] [2, 6) and records.ranges[1] [5, 8) both ask for record 5"},
  };
  std::vector<std::pair<uint32_t, uint32_t>> too_many;
  for (uint32_t i = 0; i < 4097; ++i) too_many.push_back({0, 1});
  cases.push_back({ranged("synthetic", too_many), "records: 4097 ranges, at most 4096 a request"});
  v1::StreamRequest with_resume = ranged("synthetic", {{1, 2}});
  with_resume.set_resume_offset(10);
  cases.push_back({with_resume,
                   "records cannot be combined with resume_offset or budget: a ranged request "
                   "resumes by asking for the records still missing"});
  v1::StreamRequest with_budget = ranged("synthetic", {{1, 2}});
  with_budget.mutable_budget()->set_bytes(1000);
  cases.push_back({with_budget, cases.back().message});

  for (const Case& k : cases) {
    ASSERT_TRUE(c.stream(k.request));
    v1::ServerMessage m;
    ASSERT_EQ(c.read(m), ReadEnd::kMessage);
    ASSERT_TRUE(m.has_error()) << k.message << ": " << m.DebugString();
    EXPECT_EQ(m.error().code(), v1::Error::INVALID_REQUEST);
    EXPECT_EQ(m.error().message(), k.message);
    EXPECT_FALSE(m.error().closing());
  }
  // The connection still serves a good ranged request.
  ASSERT_TRUE(c.stream(ranged("synthetic", {{5, 6}})));
  const StreamResult r = read_stream(c);
  ASSERT_TRUE(r.ok) << r.problem;
  EXPECT_EQ(r.end.reason(), v1::StreamEnd::RECORDS_SENT);
  other.join();
  EXPECT_TRUE(other_problem.empty()) << other_problem;
  EXPECT_EQ(other_bytes, models().synthetic);
}

// The server sends records before their needs when asked; the client's
// decoder refuses them until their needs are applied, and the records
// fetched in any order, applied in the order their needs allow, give
// exactly the offline decode of the same records.
TEST_F(RangedTest, RecordsBeforeTheirNeedsArriveAndTheDecoderRefusesThem) {
  const std::vector<uint8_t>& file = models().sphere;
  const StreamIndex index = *read_stream_index(file);
  const uint32_t count = static_cast<uint32_t>(index.records.size());
  ASSERT_GE(count, 6u);
  const uint32_t last = count - 1;
  TestClient c = connected();

  // The container prefix and the base mesh: an ordinary request, 1 byte.
  v1::StreamRequest base;
  base.set_model("sphere");
  base.mutable_budget()->set_bytes(1);
  ASSERT_TRUE(c.stream(base));
  const StreamResult first = read_stream(c);
  ASSERT_TRUE(first.ok) << first.problem;
  IncrementalDecoder decoder;
  ASSERT_EQ(decoder.feed(first.bytes), 1u);

  // The later half first, then the rest.
  const uint32_t middle = count / 2;
  ASSERT_TRUE(c.stream(ranged("sphere", {{middle, count}, {1, middle}})));
  const StreamResult r = read_stream(c);
  ASSERT_TRUE(r.ok) << r.problem;
  std::vector<std::vector<uint8_t>> records(count);
  for (const v1::Chunk& piece : r.chunks) {
    for (uint64_t at = piece.offset(); at < piece.offset() + piece.data().size();) {
      const uint32_t rec = record_at(index, at);
      const uint64_t stop = std::min<uint64_t>(index.records[rec].offset + index.records[rec].size,
                                               piece.offset() + piece.data().size());
      records[rec].insert(records[rec].end(),
                          piece.data().begin() + std::ptrdiff_t(at - piece.offset()),
                          piece.data().begin() + std::ptrdiff_t(stop - piece.offset()));
      at = stop;
    }
  }
  for (uint32_t rec = 1; rec < count; ++rec) {
    ASSERT_EQ(records[rec].size(), index.records[rec].size) << "record " << rec;
  }
  // Applied in arrival order, the first one is refused and nothing changes.
  auto early = decoder.feed_record(middle, records[middle]);
  ASSERT_FALSE(early);
  EXPECT_NE(early.error().message.find("needs records 1 to"), std::string::npos)
      << early.error().message;
  EXPECT_EQ(decoder.records_decoded(), 1u);
  // In the order their needs allow, every record applies.
  for (uint32_t rec = 1; rec < count; ++rec) {
    auto applied = decoder.feed_record(rec, records[rec]);
    ASSERT_TRUE(applied) << applied.error().message;
  }
  auto offline = decode_hcs(file);
  ASSERT_TRUE(offline);
  EXPECT_EQ(decoder.mesh().positions, offline->positions);
  EXPECT_EQ(decoder.mesh().triangles, offline->triangles);
  EXPECT_EQ(last + 1, decoder.records_decoded());
}

}  // namespace
}  // namespace meshstream::nettest
