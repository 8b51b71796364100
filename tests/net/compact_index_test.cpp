// StreamRequest.compact_index (proto/meshstream.proto, RecordIndex.coded and
// count): the real meshstream-server on loopback answers a request that
// sets it with the record index range-coded once per model, and a request
// that does not with the four arrays exactly as before. Checked: the coded
// index decodes to the arrays' sizes, vertices and faces; the header frame
// (as captured off the socket) is at least 4x smaller on a real encoded
// model with >= 100 records; a model whose index the coder refuses (a
// version-2 stream with records under 4 bytes) gets the arrays either way;
// real protoc decodes the new fields.
#include <gtest/gtest.h>

#include "common/codec/container.h"
#include "common/codec/encoder.h"
#include "common/codec/record_index_coder.h"
#include "common/mesh/procedural.h"
#include "server/synthetic_stream.h"
#include "tests/net/greeted_client.h"
#include "tests/net/net_harness.h"

namespace meshstream::nettest {
namespace {

namespace fs = std::filesystem;

struct CompactModels {
  std::string dir;
  std::vector<uint8_t> demo;   // real encoder, container 3, >= 100 records
  std::vector<uint8_t> small;  // synthetic container 2, 60 records
  std::vector<uint8_t> tiny;   // synthetic container 2, records of 1-3 bytes
};

// Raw frames as they come off the socket (no re-serialization), until
// `count` frames arrived or 10 s passed.
std::vector<std::vector<uint8_t>> raw_frames(TestClient& c, size_t count) {
  proto::FrameSplitter splitter(proto::kMaxServerFrameBytes);
  std::vector<std::vector<uint8_t>> frames;
  const auto deadline = Clock::now() + 10s;
  while (frames.size() < count && Clock::now() < deadline) {
    pollfd p{c.fd(), POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    uint8_t buffer[65536];
    const ssize_t n = ::recv(c.fd(), buffer, sizeof buffer, 0);
    if (n <= 0) break;
    splitter.feed(std::span<const uint8_t>(buffer, size_t(n)));
    while (frames.size() < count) {
      auto frame = splitter.next();
      if (!frame || !*frame) break;
      frames.emplace_back((*frame)->begin(), (*frame)->end());
    }
  }
  return frames;
}

class CompactIndexTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    models_ = new CompactModels();
    CompactModels& m = *models_;
    m.dir = (fs::temp_directory_path() / ("ms_ci_" + std::to_string(::getpid()))).string();
    fs::remove_all(m.dir);
    fs::create_directories(m.dir + "/models");
    EncodeOptions options;
    options.plane_calibration = 1.0;  // one encode: the test needs a stream, not the best one
    options.asa_guidance = false;
    auto encoded = encode_hcs(make_demo_mesh(20000), options);
    ASSERT_TRUE(encoded) << encoded.error().message;
    m.demo = std::move(*encoded);
    server::SyntheticStreamOptions small;
    small.records = 60;
    small.vertices = 20000;
    small.payload_bytes = 150000;
    m.small = server::make_synthetic_hcs(small);
    server::SyntheticStreamOptions tiny;
    tiny.records = 40;
    tiny.vertices = 400;
    tiny.base_bytes = 2;
    tiny.payload_bytes = 60;  // 1-3 bytes a record: the v3 coder refuses sizes < 4
    m.tiny = server::make_synthetic_hcs(tiny);
    write_file(m.dir + "/models/demo.hcs", m.demo);
    write_file(m.dir + "/models/small.hcs", m.small);
    write_file(m.dir + "/models/tiny.hcs", m.tiny);
    server_ = new ServerProcess();
    ASSERT_TRUE(server_->start({"--models", m.dir + "/models", "--cache", "none", "--threads", "1"},
                               m.dir + "/server.log"))
        << server_->log();
  }
  static void TearDownTestSuite() {
    delete server_;
    server_ = nullptr;
    if (models_) {
      std::error_code ec;
      fs::remove_all(models_->dir, ec);
    }
    delete models_;
    models_ = nullptr;
  }
  void SetUp() override { ASSERT_NE(server_, nullptr); }

  static const std::vector<uint8_t>& bytes_of(const std::string& model) {
    return model == "demo" ? models_->demo : model == "small" ? models_->small : models_->tiny;
  }

  static v1::StreamRequest request(const std::string& model, bool compact) {
    v1::StreamRequest r;
    r.set_model(model);
    r.set_compact_index(compact);
    return r;
  }

  // The whole stream for one request on a fresh connection.
  static StreamResult fetch(const v1::StreamRequest& r) {
    TestClient c = greeted_client(server_->port());
    EXPECT_TRUE(c.stream(r));
    return read_stream(c);
  }

  // The StreamHeader frame exactly as the server wrote it.
  static std::vector<uint8_t> header_frame(const v1::StreamRequest& r) {
    TestClient c = greeted_client(server_->port());
    EXPECT_TRUE(c.stream(r));
    auto frames = raw_frames(c, 1);
    EXPECT_EQ(frames.size(), 1u);
    return frames.empty() ? std::vector<uint8_t>{} : frames[0];
  }

  static CompactModels* models_;
  static ServerProcess* server_;
};

CompactModels* CompactIndexTest::models_ = nullptr;
ServerProcess* CompactIndexTest::server_ = nullptr;

TEST_F(CompactIndexTest, CodedIndexDecodesToTheSameRecordsAsTheArrays) {
  for (const std::string model : {"demo", "small"}) {
    SCOPED_TRACE(model);
    const StreamResult plain = fetch(request(model, false));
    const StreamResult compact = fetch(request(model, true));
    ASSERT_TRUE(plain.ok) << plain.problem;
    ASSERT_TRUE(compact.ok) << compact.problem;
    EXPECT_EQ(compact.bytes, bytes_of(model));  // the stream itself is unchanged
    const v1::RecordIndex& arrays = plain.header.records();
    const v1::RecordIndex& coded = compact.header.records();
    // Each header carries one form.
    EXPECT_TRUE(arrays.coded().empty());
    EXPECT_EQ(arrays.count(), 0u);
    EXPECT_EQ(coded.sizes_size(), 0);
    EXPECT_EQ(coded.vertices_size(), 0);
    EXPECT_EQ(coded.faces_size(), 0);
    EXPECT_EQ(coded.crc32_size(), 0);
    ASSERT_EQ(coded.count(), uint32_t(arrays.sizes_size()));
    const auto* data = reinterpret_cast<const uint8_t*>(coded.coded().data());
    auto entries = decode_record_index(std::span<const uint8_t>(data, coded.coded().size()),
                                       coded.count(), compact.header.payload_offset());
    ASSERT_TRUE(entries) << entries.error().message;
    for (int i = 0; i < arrays.sizes_size(); ++i) {
      EXPECT_EQ((*entries)[i].size, arrays.sizes(i)) << "record " << i;
      EXPECT_EQ((*entries)[i].vertices, arrays.vertices(i)) << "record " << i;
      EXPECT_EQ((*entries)[i].faces, arrays.faces(i)) << "record " << i;
    }
    EXPECT_EQ(entries->back().offset + entries->back().size, compact.header.total_bytes());
    // Everything else in the header is the same.
    v1::StreamHeader a = plain.header, b = compact.header;
    a.clear_records();
    b.clear_records();
    EXPECT_EQ(a.SerializeAsString(), b.SerializeAsString());
  }
}

TEST_F(CompactIndexTest, RequestWithoutTheFlagStillGetsTheFourArraysWithCrcs) {
  for (const std::string model : {"demo", "small"}) {
    SCOPED_TRACE(model);
    const StreamResult r = fetch(request(model, false));
    ASSERT_TRUE(r.ok) << r.problem;
    auto index = read_stream_index(bytes_of(model));
    ASSERT_TRUE(index);
    const v1::RecordIndex& records = r.header.records();
    ASSERT_EQ(records.sizes_size(), int(index->records.size()));
    ASSERT_EQ(records.vertices_size(), int(index->records.size()));
    ASSERT_EQ(records.faces_size(), int(index->records.size()));
    ASSERT_EQ(records.crc32_size(), int(index->records.size()));
    for (size_t i = 0; i < index->records.size(); ++i) {
      EXPECT_EQ(records.sizes(int(i)), index->records[i].size);
      EXPECT_EQ(records.vertices(int(i)), index->records[i].vertices);
      EXPECT_EQ(records.faces(int(i)), index->records[i].faces);
      EXPECT_EQ(records.crc32(int(i)), index->records[i].crc32);
      EXPECT_NE(records.crc32(int(i)), 0u);  // real CRCs of random or encoded payloads
    }
  }
}

TEST_F(CompactIndexTest, HeaderFrameIsAtLeastFourTimesSmallerOnARealModel) {
  auto index = read_stream_index(models_->demo);
  ASSERT_TRUE(index);
  ASSERT_GE(index->records.size(), 100u) << "the test model should have >= 100 records";
  const std::vector<uint8_t> plain = header_frame(request("demo", false));
  const std::vector<uint8_t> compact = header_frame(request("demo", true));
  ASSERT_FALSE(plain.empty());
  ASSERT_FALSE(compact.empty());
  EXPECT_GE(plain.size(), 4 * compact.size())
      << index->records.size() << " records: " << plain.size() << " vs " << compact.size()
      << " bytes";
  std::printf(
      "[ demo model ] %zu records: StreamHeader frame %zu bytes (arrays) vs %zu (compact)\n",
      index->records.size(), plain.size(), compact.size());
}

TEST_F(CompactIndexTest, ResumedRequestStillGetsEveryRecordCoded) {
  auto index = read_stream_index(models_->demo);
  ASSERT_TRUE(index);
  v1::StreamRequest r = request("demo", true);
  r.set_resume_offset(index->records[index->records.size() / 2].offset);
  const StreamResult resumed = fetch(r);
  ASSERT_TRUE(resumed.ok) << resumed.problem;
  EXPECT_EQ(resumed.header.first_record(), index->records.size() / 2);
  const v1::RecordIndex& coded = resumed.header.records();
  ASSERT_EQ(coded.count(), index->records.size());
  const auto* data = reinterpret_cast<const uint8_t*>(coded.coded().data());
  auto entries = decode_record_index(std::span<const uint8_t>(data, coded.coded().size()),
                                     coded.count(), resumed.header.payload_offset());
  ASSERT_TRUE(entries) << entries.error().message;
  for (size_t i = 0; i < index->records.size(); ++i) {
    EXPECT_EQ((*entries)[i].offset, index->records[i].offset) << "record " << i;
    EXPECT_EQ((*entries)[i].vertices, index->records[i].vertices) << "record " << i;
  }
  EXPECT_TRUE(std::equal(resumed.bytes.begin(), resumed.bytes.end(),
                         models_->demo.begin() + std::ptrdiff_t(resumed.header.start_offset())));
}

TEST_F(CompactIndexTest, ModelTheCoderRefusesGetsTheArraysEvenWhenAsked) {
  auto index = read_stream_index(models_->tiny);
  ASSERT_TRUE(index);
  ASSERT_FALSE(encode_record_index(index->records))
      << "the tiny model was expected to be uncodable";
  const StreamResult r = fetch(request("tiny", true));
  ASSERT_TRUE(r.ok) << r.problem;
  EXPECT_EQ(r.bytes, models_->tiny);
  EXPECT_EQ(r.header.records().count(), 0u);
  EXPECT_TRUE(r.header.records().coded().empty());
  ASSERT_EQ(r.header.records().sizes_size(), int(index->records.size()));
  ASSERT_EQ(r.header.records().crc32_size(), int(index->records.size()));
  for (size_t i = 0; i < index->records.size(); ++i) {
    EXPECT_EQ(r.header.records().sizes(int(i)), index->records[i].size);
  }
  EXPECT_NE(server_->log().find("tiny: its record index cannot be coded compactly"),
            std::string::npos)
      << server_->log();
}

TEST_F(CompactIndexTest, CapturedCompactHeaderDecodesWithRealProtoc) {
  const std::vector<uint8_t> frame = header_frame(request("small", true));
  ASSERT_FALSE(frame.empty());
  const std::string bin = models_->dir + "/compact_header.bin";
  const std::string txt = models_->dir + "/compact_header.txt";
  write_file(bin, frame);
  const std::string cmd = std::string(MESHSTREAM_PROTOC) + " -I " + MESHSTREAM_SOURCE_DIR +
                          " --decode meshstream.v1.ServerMessage proto/meshstream.proto < " + bin +
                          " > " + txt + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::ifstream in(txt);
  std::stringstream s;
  s << in.rdbuf();
  const std::string text = s.str();
  EXPECT_NE(text.find("records {"), std::string::npos) << text.substr(0, 2000);
  EXPECT_NE(text.find("coded: \""), std::string::npos) << text.substr(0, 2000);
  EXPECT_NE(text.find("count: 60"), std::string::npos) << text.substr(0, 2000);
  EXPECT_EQ(text.find("sizes:"), std::string::npos) << text.substr(0, 2000);
  EXPECT_EQ(text.find("crc32:"), std::string::npos) << text.substr(0, 2000);
  // Unknown fields would show as bare numbers ("5: ...").
  EXPECT_EQ(text.find("\n  5:"), std::string::npos) << text.substr(0, 2000);
}

}  // namespace
}  // namespace meshstream::nettest
