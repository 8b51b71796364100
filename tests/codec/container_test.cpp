#include "common/codec/container.h"

#include <gtest/gtest.h>

#include "common/codec/crc32.h"
#include "tests/codec/container_test_util.h"

namespace meshstream {
namespace {

TEST(Crc32, MatchesKnownValue) {
  const char* text = "123456789";
  EXPECT_EQ(crc32(0, reinterpret_cast<const uint8_t*>(text), 9), 0xCBF43926u);
}

std::vector<uint8_t> sample_stream(StreamIndex* expected) {
  StreamHeader header;
  header.vertex_count = 30;
  header.face_count = 56;
  header.base_vertex_count = 10;
  header.base_face_count = 16;
  header.bounds = {{-1, -2, -3}, {1, 2, 3}};
  header.layer_count = 2;
  std::vector<std::vector<uint8_t>> payloads = {{1, 2, 3}, {4, 5}, {6, 7, 8, 9}};
  std::vector<RecordEntry> records(3);
  uint32_t v[] = {10, 20, 30}, f[] = {16, 36, 56};
  for (int i = 0; i < 3; ++i) {
    records[i].size = static_cast<uint32_t>(payloads[i].size());
    records[i].vertices = v[i];
    records[i].faces = f[i];
    records[i].crc32 = crc32(0, payloads[i].data(), payloads[i].size());
  }
  std::vector<uint8_t> bytes = write_container_prefix(header, records);
  for (auto& p : payloads) bytes.insert(bytes.end(), p.begin(), p.end());
  if (expected) {
    expected->header = header;
    expected->records = records;
  }
  return bytes;
}

TEST(Container, IndexRoundTrips) {
  StreamIndex expected;
  std::vector<uint8_t> bytes = sample_stream(&expected);
  auto index = read_stream_index(bytes);
  ASSERT_TRUE(index) << index.error().message;
  EXPECT_EQ(index->header.vertex_count, 30u);
  EXPECT_EQ(index->header.bounds.max.z, 3.0f);
  ASSERT_EQ(index->records.size(), 3u);
  EXPECT_EQ(index->total_bytes(), bytes.size());
  for (size_t i = 0; i < 3; ++i) {
    const RecordEntry& r = index->records[i];
    EXPECT_EQ(r.offset, expected.records[i].offset);
    EXPECT_TRUE(record_intact(r, std::span(bytes).subspan(r.offset, r.size)));
  }
}

TEST(Container, EveryShortPrefixIsTruncatedNotAnError) {
  std::vector<uint8_t> bytes = sample_stream(nullptr);
  auto full = read_stream_index(bytes);
  ASSERT_TRUE(full);
  testing::expect_every_short_prefix_truncated(bytes, full->payload_offset);
}

TEST(Container, EveryFlippedHeaderBitIsDetected) {
  std::vector<uint8_t> bytes = sample_stream(nullptr);
  auto full = read_stream_index(bytes);
  ASSERT_TRUE(full);
  for (size_t i = 0; i < full->payload_offset; ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      std::vector<uint8_t> bad = bytes;
      bad[i] ^= uint8_t(1 << bit);
      auto index = read_stream_index(bad);
      EXPECT_FALSE(index) << "byte " << i << " bit " << bit;
    }
  }
}

}  // namespace
}  // namespace meshstream
