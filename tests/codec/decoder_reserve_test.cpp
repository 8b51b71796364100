// The decoder reserves its arrays once for the size it will reach instead of
// letting them grow by doubling, but only for what its caller feeds: the
// encoder's measurements decode prefixes of their streams (an eighth of the
// bytes, the guidance's groups), and reserving the whole stream's size there
// raised the encoder's peak heap by a third (EncoderMemory).
#include <gtest/gtest.h>

#include <span>
#include <vector>

#include "common/codec/container.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "tests/codec/codec_test_util.h"

namespace meshstream {
namespace {

TEST(DecoderReserve, APrefixReservesForItselfAndStillDecodesPastIt) {
  auto stream = encode_hcs(testing::icosphere(5, 0.2f));
  ASSERT_TRUE(stream) << stream.error().message;
  auto index = read_stream_index(*stream);
  ASSERT_TRUE(index);
  ASSERT_GE(index->records.size(), 4u);
  const RecordEntry& middle = index->records[index->records.size() / 2];
  const uint64_t prefix = middle.offset + middle.size;
  const std::span<const uint8_t> bytes(*stream);

  // Without a hint, a whole prefix fed at once reserves the stream's size
  // (eight vertices a byte is a bound the prefix's bytes reach).
  IncrementalDecoder whole;
  ASSERT_TRUE(whole.feed(bytes.first(prefix)));
  ASSERT_EQ(whole.mesh().vertex_count(), middle.vertices);
  EXPECT_EQ(whole.mesh().positions.capacity(), index->header.vertex_count);

  // With it, exactly the prefix's counts.
  IncrementalDecoder hinted;
  hinted.expect_prefix(prefix);
  ASSERT_TRUE(hinted.feed(bytes.first(prefix)));
  ASSERT_EQ(hinted.mesh().vertex_count(), middle.vertices);
  EXPECT_EQ(hinted.mesh().positions.capacity(), middle.vertices);
  EXPECT_EQ(hinted.mesh().triangles.capacity(), middle.faces);
  EXPECT_EQ(hinted.mesh().positions, whole.mesh().positions);
  EXPECT_EQ(hinted.mesh().triangles, whole.mesh().triangles);

  // Capacity only: the rest of the stream still decodes, to the full mesh.
  ASSERT_TRUE(hinted.feed(bytes.subspan(prefix)));
  EXPECT_TRUE(hinted.finished());
  auto full = decode_hcs(bytes);
  ASSERT_TRUE(full);
  EXPECT_EQ(hinted.mesh().positions, full->positions);
  EXPECT_EQ(hinted.mesh().triangles, full->triangles);
}

TEST(DecoderReserve, AHintBeforeTheFirstRecordReservesTheBase) {
  auto stream = encode_hcs(testing::icosphere(4, 0.2f));
  ASSERT_TRUE(stream) << stream.error().message;
  auto index = read_stream_index(*stream);
  ASSERT_TRUE(index);
  IncrementalDecoder decoder;
  decoder.expect_prefix(index->records[0].offset);  // ends before the base does
  ASSERT_TRUE(decoder.feed(*stream));
  EXPECT_TRUE(decoder.finished());
  EXPECT_EQ(decoder.mesh().vertex_count(), index->header.vertex_count);
}

}  // namespace
}  // namespace meshstream
