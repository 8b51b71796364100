// IncrementalDecoder::feed_record: records given one by one, as a ranged
// request delivers them in whatever order the client asked. The decoder
// applies a record only once its needs are applied and refuses the rest
// without changing its mesh.
#include <gtest/gtest.h>

#include <span>
#include <string>
#include <vector>

#include "common/codec/container.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "tests/codec/codec_test_util.h"

namespace meshstream {
namespace {

struct Sample {
  std::vector<uint8_t> stream;
  StreamIndex index;
};

const Sample& sample() {
  static const Sample s = [] {
    Sample out;
    auto stream = encode_hcs(testing::icosphere(4, 0.2f));
    EXPECT_TRUE(stream) << stream.error().message;
    out.stream = *stream;
    out.index = *read_stream_index(out.stream);
    return out;
  }();
  return s;
}

std::span<const uint8_t> record_bytes(uint32_t record) {
  const RecordEntry& r = sample().index.records[record];
  return std::span<const uint8_t>(sample().stream).subspan(r.offset, r.size);
}

// A decoder that holds the container prefix and nothing else.
IncrementalDecoder with_prefix_only() {
  IncrementalDecoder decoder;
  const auto prefix =
      std::span<const uint8_t>(sample().stream).first(sample().index.payload_offset);
  EXPECT_EQ(decoder.feed(prefix), 0u);
  EXPECT_NE(decoder.index(), nullptr);
  return decoder;
}

TEST(FeedRecord, RecordsOneByOneDecodeTheSameMeshAsTheStream) {
  const uint32_t count = static_cast<uint32_t>(sample().index.records.size());
  ASSERT_GE(count, 5u);
  IncrementalDecoder decoder = with_prefix_only();
  for (uint32_t r = 0; r < count; ++r) {
    auto applied = decoder.feed_record(r, record_bytes(r));
    ASSERT_TRUE(applied) << applied.error().message;
    EXPECT_EQ(*applied, 1u);
    EXPECT_EQ(decoder.records_decoded(), r + 1);
  }
  EXPECT_TRUE(decoder.finished());
  auto whole = decode_hcs(sample().stream);
  ASSERT_TRUE(whole);
  EXPECT_EQ(decoder.mesh().positions, whole->positions);
  EXPECT_EQ(decoder.mesh().triangles, whole->triangles);
}

TEST(FeedRecord, ARecordBeforeItsNeedsIsRefusedAndChangesNothing) {
  IncrementalDecoder decoder = with_prefix_only();
  const uint32_t count = static_cast<uint32_t>(sample().index.records.size());
  const std::string of = " of " + std::to_string(count);

  auto early = decoder.feed_record(3, record_bytes(3));
  ASSERT_FALSE(early);
  EXPECT_EQ(
      early.error().message,
      "record 3" + of + ": needs records 0 to 2 first (a record needs every record before it)");
  EXPECT_EQ(decoder.records_decoded(), 0u);

  ASSERT_TRUE(decoder.feed_record(0, record_bytes(0)));
  ASSERT_TRUE(decoder.feed_record(1, record_bytes(1)));
  const Mesh after_two = decoder.mesh();
  auto skip = decoder.feed_record(3, record_bytes(3));
  ASSERT_FALSE(skip);
  EXPECT_EQ(skip.error().message,
            "record 3" + of + ": needs record 2 first (a record needs every record before it)");
  auto again = decoder.feed_record(1, record_bytes(1));
  ASSERT_FALSE(again);
  EXPECT_EQ(again.error().message, "record 1" + of + ": already applied");
  auto past = decoder.feed_record(count, record_bytes(1));
  ASSERT_FALSE(past);
  EXPECT_EQ(past.error().message, "record " + std::to_string(count) + of + ": no such record");
  auto short_bytes = decoder.feed_record(2, record_bytes(2).first(record_bytes(2).size() - 1));
  ASSERT_FALSE(short_bytes);
  EXPECT_NE(short_bytes.error().message.find("record 2" + of + ": is "), std::string::npos)
      << short_bytes.error().message;
  // None of these touched the mesh, and the decoder goes on.
  EXPECT_EQ(decoder.records_decoded(), 2u);
  EXPECT_EQ(decoder.mesh().positions, after_two.positions);
  EXPECT_EQ(decoder.mesh().triangles, after_two.triangles);
  ASSERT_TRUE(decoder.feed_record(2, record_bytes(2)));
  ASSERT_TRUE(decoder.feed_record(3, record_bytes(3)));
  EXPECT_EQ(decoder.records_decoded(), 4u);
}

TEST(FeedRecord, AlteredBytesFailTheirChecksumAndTheRightBytesStillApply) {
  IncrementalDecoder decoder = with_prefix_only();
  ASSERT_TRUE(decoder.feed_record(0, record_bytes(0)));
  std::vector<uint8_t> altered(record_bytes(1).begin(), record_bytes(1).end());
  altered[altered.size() / 2] ^= 0x40;
  auto bad = decoder.feed_record(1, altered);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("checksum mismatch"), std::string::npos)
      << bad.error().message;
  EXPECT_TRUE(decoder.error_is_recoverable());
  EXPECT_EQ(decoder.records_decoded(), 1u);
  auto good = decoder.feed_record(1, record_bytes(1));
  ASSERT_TRUE(good) << good.error().message;
  EXPECT_EQ(decoder.records_decoded(), 2u);
}

TEST(FeedRecord, NoIndexNoRecord) {
  IncrementalDecoder decoder;
  auto refused = decoder.feed_record(0, record_bytes(0));
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().message, "record 0: the stream's index has not arrived");
}

}  // namespace
}  // namespace meshstream
