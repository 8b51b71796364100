// Budget.percent_vertices (HCS's "percentage of points"): the server ends a
// stream on exactly the record `meshstream decode --percent` decodes to,
// because both use prefix_for_budget (common/codec/decoder.h). Checked on
// synthetic indexes (stream_plan alone) and over a real socket against the
// real server binary serving the procedural demo model. Bad values (NaN, 0,
// negative, > 100, infinite) are INVALID_REQUEST naming the value, and the
// connection stays usable.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/procedural.h"
#include "server/stream_plan.h"
#include "server/synthetic_stream.h"
#include "tests/net/greeted_client.h"
#include "tests/net/net_harness.h"

namespace meshstream::nettest {
namespace {

namespace fs = std::filesystem;

// The definition, written out independently of prefix_for_budget: the
// number of records whose cumulative vertex count is <= P % of the full
// mesh's, at least 1 (the base mesh). Vertex counts never decrease along a
// stream, so these records are a prefix.
uint32_t records_by_definition(const StreamIndex& index, double percent) {
  const double limit = percent / 100.0 * double(index.header.vertex_count);
  uint32_t n = 0;
  while (n < index.records.size() && double(index.records[n].vertices) <= limit + 1e-9) ++n;
  return std::max<uint32_t>(n, 1);
}

// Records that prefix_for_budget's prefix holds.
uint32_t records_by_decoder(const StreamIndex& index, double percent) {
  const uint64_t prefix =
      prefix_for_budget(index, DecodeBudget{DecodeBudget::Kind::kPercentVertices, percent});
  return server::records_complete_at(index, prefix);
}

// Percents that fall between records, exactly on a record's vertex share,
// and the ends of the range.
std::vector<double> interesting_percents(const StreamIndex& index) {
  std::vector<double> out{1e-6, 0.5, 5, 12.5, 33.3, 50, 66.7, 90, 99.99, 100};
  const double total = double(index.header.vertex_count);
  for (size_t r = 0; r < index.records.size(); r += std::max<size_t>(1, index.records.size() / 7)) {
    out.push_back(100.0 * double(index.records[r].vertices) / total);
  }
  return out;
}

TEST(PercentVerticesPlan, EndsWhereTheDecoderBudgetEnds) {
  server::SyntheticStreamOptions o;
  o.records = 80;
  o.vertices = 30000;
  o.payload_bytes = 200000;
  const std::vector<uint8_t> bytes = server::make_synthetic_hcs(o);
  auto index = read_stream_index(bytes);
  ASSERT_TRUE(index);
  for (double p : interesting_percents(*index)) {
    auto plan = server::plan_stream(*index, 0, Budget::percent_vertices(p));
    ASSERT_TRUE(plan) << p << ": " << plan.error().message;
    EXPECT_EQ(plan->end_record, records_by_decoder(*index, p)) << p;
    EXPECT_EQ(plan->end_record, records_by_definition(*index, p)) << p;
    EXPECT_EQ(plan->end, prefix_for_budget(*index, {DecodeBudget::Kind::kPercentVertices, p})) << p;
    EXPECT_EQ(plan->complete, plan->end_record == index->records.size()) << p;
  }
  EXPECT_TRUE(server::plan_stream(*index, 0, Budget::percent_vertices(100))->complete);
  // Resumed past the budget: nothing to send, as for every other budget.
  auto late =
      server::plan_stream(*index, index->records[70].offset, Budget::percent_vertices(1e-6));
  ASSERT_TRUE(late);
  EXPECT_EQ(late->start, late->end);
}

TEST(PercentVerticesPlan, RefusesValuesOutsideTheRangeNamingThem) {
  server::SyntheticStreamOptions o;
  o.records = 10;
  const std::vector<uint8_t> bytes = server::make_synthetic_hcs(o);
  auto index = read_stream_index(bytes);
  ASSERT_TRUE(index);
  const double inf = std::numeric_limits<double>::infinity();
  const struct {
    double value;
    const char* shown;
  } cases[] = {{std::nan(""), "nan"},        {0, " 0 "},   {-0.0, " -0 "}, {-5, "-5"}, {101, "101"},
               {100.0000001, "100.0000001"}, {inf, "inf"}, {-inf, "-inf"}};
  for (const auto& c : cases) {
    auto plan = server::plan_stream(*index, 0, Budget::percent_vertices(c.value));
    ASSERT_FALSE(plan) << c.shown;
    EXPECT_EQ(plan.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(plan.error().message.find("percent_vertices"), std::string::npos)
        << plan.error().message;
    EXPECT_NE(plan.error().message.find(c.shown), std::string::npos) << plan.error().message;
  }
  // The bytes percent names its value the same way.
  auto bytes_plan = server::plan_stream(*index, 0, Budget::percent_bytes(101));
  ASSERT_FALSE(bytes_plan);
  EXPECT_NE(bytes_plan.error().message.find("101"), std::string::npos)
      << bytes_plan.error().message;
}

// The real server on loopback, serving the procedural demo model encoded
// with the default (embedded: plane records) encoder.
class PercentVerticesServerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(
        (fs::temp_directory_path() / ("ms_pv_" + std::to_string(::getpid()))).string());
    fs::remove_all(*dir_);
    fs::create_directories(*dir_ + "/models");
    EncodeOptions options;
    options.plane_calibration = 1.0;  // one encode: the test needs a stream, not the best one
    options.asa_guidance = false;
    auto encoded = encode_hcs(make_demo_mesh(20000), options);
    ASSERT_TRUE(encoded) << encoded.error().message;
    stream_ = new std::vector<uint8_t>(std::move(*encoded));
    write_file(*dir_ + "/models/demo.hcs", *stream_);
    server_ = new ServerProcess();
    ASSERT_TRUE(
        server_->start({"--models", *dir_ + "/models", "--threads", "1"}, *dir_ + "/server.log"))
        << server_->log();
  }
  static void TearDownTestSuite() {
    delete server_;
    server_ = nullptr;
    delete stream_;
    stream_ = nullptr;
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
    dir_ = nullptr;
  }

  static TestClient connected() { return greeted_client(server_->port()); }

  static v1::StreamRequest percent_request(double p) {
    v1::StreamRequest request;
    request.set_model("demo");
    request.mutable_budget()->set_percent_vertices(p);
    return request;
  }

  static std::string* dir_;
  static std::vector<uint8_t>* stream_;
  static ServerProcess* server_;
};

std::string* PercentVerticesServerTest::dir_ = nullptr;
std::vector<uint8_t>* PercentVerticesServerTest::stream_ = nullptr;
ServerProcess* PercentVerticesServerTest::server_ = nullptr;

TEST_F(PercentVerticesServerTest, StreamEndsOnTheDecodersRecordAndVertexCount) {
  auto index = read_stream_index(*stream_);
  ASSERT_TRUE(index);
  uint32_t plane_records = 0;  // records that keep the vertex count
  for (size_t r = 1; r < index->records.size(); ++r) {
    plane_records += index->records[r].vertices == index->records[r - 1].vertices;
  }
  EXPECT_GT(plane_records, 0u) << "the demo stream was expected to hold plane records";
  TestClient c = connected();
  for (double p : {10.0, 37.5, 50.0, 80.0, 100.0}) {
    ASSERT_TRUE(c.stream(percent_request(p)));
    const StreamResult r = read_stream(c);
    ASSERT_TRUE(r.ok) << p << ": " << r.problem;
    const uint32_t expected = records_by_decoder(*index, p);
    EXPECT_EQ(expected, records_by_definition(*index, p)) << p;
    EXPECT_EQ(r.header.end_record(), expected) << p;
    EXPECT_EQ(r.end.records_complete(), expected) << p;
    EXPECT_EQ(r.end.reason(),
              expected == index->records.size() ? v1::StreamEnd::COMPLETE : v1::StreamEnd::BUDGET);
    ASSERT_EQ(r.bytes.size(), prefix_for_budget(*index, {DecodeBudget::Kind::kPercentVertices, p}))
        << p;
    EXPECT_TRUE(std::equal(r.bytes.begin(), r.bytes.end(), stream_->begin())) << p;
    // Decoding what arrived gives the decoder's own budgeted mesh.
    IncrementalDecoder decoder;
    ASSERT_TRUE(decoder.feed(r.bytes));
    EXPECT_EQ(decoder.records_decoded(), expected) << p;
    EXPECT_EQ(decoder.mesh().vertex_count(), index->records[expected - 1].vertices) << p;
    EXPECT_LE(double(decoder.mesh().vertex_count()),
              p / 100.0 * double(index->header.vertex_count) + 1e-9)
        << p;
  }
}

TEST_F(PercentVerticesServerTest, OutOfRangeIsAnInvalidRequestThatKeepsTheConnection) {
  TestClient c = connected();
  for (double bad : {std::nan(""), 0.0, 101.0}) {
    ASSERT_TRUE(c.stream(percent_request(bad)));
    const StreamResult r = read_stream(c);
    ASSERT_TRUE(r.error.has_value()) << bad;
    EXPECT_EQ(r.error->code(), v1::Error::INVALID_REQUEST);
    EXPECT_FALSE(r.error->closing());
    EXPECT_NE(r.error->message().find("percent_vertices"), std::string::npos) << r.error->message();
  }
  ASSERT_TRUE(c.stream(percent_request(25)));
  EXPECT_TRUE(read_stream(c).ok);
}

}  // namespace
}  // namespace meshstream::nettest
