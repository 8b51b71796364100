// facts_from_header (client/stream_facts.h): the client's StreamFacts are the
// same whichever form of RecordIndex the server sent (proto/meshstream.proto:
// the four arrays, or the compact coded form asked for with
// StreamRequest.compact_index), and a compact index that does not decode or
// disagrees with the header (count, total_bytes, end_record, the full
// mesh's counts) is refused with an error naming the problem. Hostile
// inputs (random bytes, huge counts) end in an error, never a crash or a
// huge allocation.
#include "client/stream_facts.h"

#include <gtest/gtest.h>

#include <random>

#include "common/codec/container.h"
#include "common/codec/record_index_coder.h"

namespace meshstream::client {
namespace {

// A plausible index: a base, structure records growing, a few plane records.
std::vector<RecordEntry> sample_records(uint64_t payload_offset, uint32_t count) {
  std::vector<RecordEntry> records(count);
  uint64_t at = payload_offset;
  uint32_t vertices = 0, faces = 0;
  for (uint32_t i = 0; i < count; ++i) {
    RecordEntry& r = records[i];
    r.offset = at;
    const bool plane = i > 0 && i % 9 == 0;
    r.size = i == 0 ? 900 : plane ? 120 + i : 60 + 3 * i;
    const uint32_t added = i == 0 ? 150 : plane ? 0 : 10 + i / 4;
    vertices += added;
    faces = i == 0 ? 296 : faces + 2 * added;
    r.vertices = vertices;
    r.faces = faces;
    r.crc32 = 0x1234567u + i;
    at += r.size;
  }
  return records;
}

v1::StreamHeader header_for(const std::vector<RecordEntry>& records, uint64_t payload_offset) {
  v1::StreamHeader h;
  h.set_model("sample");
  h.set_total_bytes(records.back().offset + records.back().size);
  h.set_start_offset(0);
  h.set_end_offset(h.total_bytes());
  h.set_payload_offset(payload_offset);
  h.set_first_record(0);
  h.set_end_record(uint32_t(records.size()));
  h.set_vertices(records.back().vertices);
  h.set_faces(records.back().faces);
  h.set_base_vertices(records[0].vertices);
  h.set_base_faces(records[0].faces);
  h.set_quant_bits(12);
  h.set_container_version(3);
  return h;
}

void set_arrays(v1::StreamHeader& h, const std::vector<RecordEntry>& records) {
  for (const RecordEntry& r : records) {
    h.mutable_records()->add_sizes(r.size);
    h.mutable_records()->add_vertices(r.vertices);
    h.mutable_records()->add_faces(r.faces);
    h.mutable_records()->add_crc32(r.crc32);
  }
}

void set_coded(v1::StreamHeader& h, const std::vector<uint8_t>& coded, uint32_t count) {
  h.mutable_records()->set_coded(coded.data(), coded.size());
  h.mutable_records()->set_count(count);
}

class StreamFactsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    records_ = sample_records(kPayloadOffset, 180);
    auto coded = encode_record_index(records_);
    ASSERT_TRUE(coded) << coded.error().message;
    coded_ = std::move(*coded);
    arrays_ = header_for(records_, kPayloadOffset);
    set_arrays(arrays_, records_);
    compact_ = header_for(records_, kPayloadOffset);
    set_coded(compact_, coded_, uint32_t(records_.size()));
  }

  // The refusal of `h`, with the problem text it must name.
  static void expect_refused(const v1::StreamHeader& h, const std::string& named) {
    auto f = facts_from_header(h);
    ASSERT_FALSE(f) << "accepted: " << named;
    EXPECT_TRUE(f.error().code == ErrorCode::kParse || f.error().code == ErrorCode::kCorrupt)
        << f.error().message;
    EXPECT_NE(f.error().message.find("compact record index"), std::string::npos)
        << f.error().message;
    EXPECT_NE(f.error().message.find("'sample'"), std::string::npos) << f.error().message;
    EXPECT_NE(f.error().message.find(named), std::string::npos) << f.error().message;
  }

  static constexpr uint64_t kPayloadOffset = 412;
  std::vector<RecordEntry> records_;
  std::vector<uint8_t> coded_;
  v1::StreamHeader arrays_, compact_;
};

TEST_F(StreamFactsTest, BothFormsGiveTheSameFacts) {
  auto a = facts_from_header(arrays_);
  auto c = facts_from_header(compact_);
  ASSERT_TRUE(a) << a.error().message;
  ASSERT_TRUE(c) << c.error().message;
  EXPECT_EQ(c->records_total, records_.size());
  EXPECT_EQ(a->records_total, c->records_total);
  EXPECT_EQ(a->record_end, c->record_end);
  EXPECT_EQ(a->record_vertices, c->record_vertices);
  EXPECT_EQ(a->record_faces, c->record_faces);
  EXPECT_EQ(c->record_end.back(), compact_.total_bytes());
  for (size_t i = 0; i < records_.size(); ++i) {
    EXPECT_EQ(c->record_end[i], records_[i].offset + records_[i].size) << i;
    EXPECT_EQ(c->record_vertices[i], records_[i].vertices) << i;
    EXPECT_EQ(c->record_faces[i], records_[i].faces) << i;
  }
  EXPECT_EQ(c->model, "sample");
  EXPECT_EQ(c->total_bytes, a->total_bytes);
  EXPECT_EQ(c->payload_offset, kPayloadOffset);
  EXPECT_EQ(c->end_record, records_.size());
  EXPECT_EQ(c->vertices, records_.back().vertices);
  // The compact form is what makes the header small.
  EXPECT_LT(compact_.ByteSizeLong() * 4, arrays_.ByteSizeLong());
}

TEST_F(StreamFactsTest, ArraysFormIsReadAsBefore) {
  // Shorter count arrays read as 0, as the client always did.
  v1::StreamHeader h = header_for(records_, kPayloadOffset);
  for (const RecordEntry& r : records_) h.mutable_records()->add_sizes(r.size);
  auto f = facts_from_header(h);
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_EQ(f->records_total, records_.size());
  EXPECT_EQ(f->record_vertices.back(), 0u);
  EXPECT_EQ(f->record_end.back(), h.total_bytes());
}

TEST_F(StreamFactsTest, GarbageCodedIndexIsRefused) {
  v1::StreamHeader h = compact_;
  const std::vector<uint8_t> garbage(coded_.size(), 0xff);
  set_coded(h, garbage, uint32_t(records_.size()));
  expect_refused(h, "does not decode");
}

TEST_F(StreamFactsTest, TruncatedCodedIndexIsRefused) {
  for (size_t keep : {size_t(0), size_t(1), coded_.size() / 2, coded_.size() - 1}) {
    SCOPED_TRACE(keep);
    v1::StreamHeader h = compact_;
    set_coded(h, std::vector<uint8_t>(coded_.begin(), coded_.begin() + std::ptrdiff_t(keep)),
              uint32_t(records_.size()));
    auto f = facts_from_header(h);
    ASSERT_FALSE(f);
    EXPECT_NE(f.error().message.find("compact record index"), std::string::npos)
        << f.error().message;
  }
}

TEST_F(StreamFactsTest, WrongCountIsRefused) {
  const auto n = uint32_t(records_.size());
  for (uint32_t count : {n - 1, n + 1, 2 * n, 1u}) {
    SCOPED_TRACE(count);
    v1::StreamHeader h = compact_;
    h.set_end_record(std::min(count, n));
    set_coded(h, coded_, count);
    auto f = facts_from_header(h);
    ASSERT_FALSE(f);
    EXPECT_NE(f.error().message.find("compact record index"), std::string::npos)
        << f.error().message;
  }
  v1::StreamHeader none = compact_;
  none.mutable_records()->set_count(0);
  expect_refused(none, "no record count");
}

TEST_F(StreamFactsTest, HugeCountFailsBeforeAllocating) {
  for (uint32_t count : {kMaxRecords + 1, 0xffffffffu}) {
    v1::StreamHeader h = compact_;
    set_coded(h, coded_, count);
    expect_refused(h, "more than a stream may hold");
  }
  // Within kMaxRecords but far more than the bytes can hold.
  v1::StreamHeader h = compact_;
  set_coded(h, coded_, kMaxRecords);
  expect_refused(h, "does not decode");
}

TEST_F(StreamFactsTest, IndexThatDisagreesWithTheHeaderIsRefused) {
  v1::StreamHeader total = compact_;
  total.set_total_bytes(compact_.total_bytes() + 1);
  expect_refused(total, "total_bytes");

  v1::StreamHeader offset = compact_;  // shifts every record's end
  offset.set_payload_offset(kPayloadOffset + 8);
  expect_refused(offset, "total_bytes");

  v1::StreamHeader end = compact_;
  end.set_end_record(uint32_t(records_.size()) + 1);
  expect_refused(end, "end_record");

  v1::StreamHeader counts = compact_;
  counts.set_vertices(records_.back().vertices + 1);
  expect_refused(counts, "vertices");

  v1::StreamHeader both = compact_;
  set_arrays(both, records_);
  expect_refused(both, "record arrays too");
}

TEST_F(StreamFactsTest, RandomCodedBytesNeverCrash) {
  std::mt19937 rng(7);
  int accepted = 0;
  for (int round = 0; round < 3000; ++round) {
    std::vector<uint8_t> bytes(rng() % 64);
    for (auto& b : bytes) b = uint8_t(rng());
    // Sometimes a real prefix with its tail altered.
    if (round % 3 == 0) {
      bytes.assign(coded_.begin(), coded_.end());
      bytes[rng() % bytes.size()] ^= uint8_t(1u << (rng() % 8));
    }
    v1::StreamHeader h = compact_;
    const uint32_t count = round % 3 == 0 ? uint32_t(records_.size()) : 1 + rng() % 400;
    h.set_end_record(std::min<uint32_t>(count, h.end_record()));
    set_coded(h, bytes, count);
    auto f = facts_from_header(h);
    if (!f) continue;
    // Whatever is accepted is consistent with the header.
    ++accepted;
    ASSERT_EQ(f->records_total, count);
    ASSERT_EQ(f->record_end.size(), count);
    EXPECT_EQ(f->record_end.back(), h.total_bytes());
    EXPECT_TRUE(std::is_sorted(f->record_end.begin(), f->record_end.end()));
  }
  std::printf("[ random ] %d of 3000 altered indexes still matched the header\n", accepted);
}

}  // namespace
}  // namespace meshstream::client
