// Refinement format 3 (faster-learning models, finer valence and rank
// contexts) against format 2, which the encoder still writes on request:
// both decode to the quantized input exactly, carry their format in the
// header, and differ in bytes; an unknown format is refused. FastStartBitModel's
// schedule is checked against the coder it replaces.
#include <gtest/gtest.h>

#include <random>

#include "common/codec/container.h"
#include "common/codec/decimate.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/codec/range_coder.h"
#include "tests/codec/codec_test_util.h"

namespace meshstream {
namespace {

using namespace meshstream::testing;

TEST(RefinementFormat, BothFormatsDecodeExactly) {
  const Mesh mesh = combine({icosphere(3, 0.15f), torus(24, 12), height_field(12, 9)});
  auto reference = quantized_reference(mesh, 12);
  ASSERT_TRUE(reference);
  std::vector<uint8_t> streams[2];
  for (int i = 0; i < 2; ++i) {
    const int format = i == 0 ? kRefinementFormatEmbedded : kRefinementFormat;
    EncodeOptions options;
    options.refinement_format = static_cast<RefinementFormat>(format);
    options.plane_calibration = 3.0;
    auto bytes = encode_hcs(mesh, options);
    ASSERT_TRUE(bytes) << bytes.error().message;
    auto index = read_stream_index(*bytes);
    ASSERT_TRUE(index);
    ASSERT_GE(index->header.extra.size(), 1u);
    EXPECT_EQ(index->header.extra[0], format);
    auto decoded = decode_hcs(*bytes);
    ASSERT_TRUE(decoded) << "format " << format << ": " << decoded.error().message;
    EXPECT_EQ(sorted_positions(*decoded), sorted_positions(*reference)) << "format " << format;
    EXPECT_EQ(canonical_faces(*decoded), canonical_faces(*reference)) << "format " << format;
    streams[i] = std::move(*bytes);
  }
  EXPECT_NE(streams[0], streams[1]) << "format 3 codes the records with other models";
}

TEST(RefinementFormat, DefaultIsFormat3AndUnknownFormatsAreRefused) {
  const Mesh mesh = icosphere(2);
  auto bytes = encode_hcs(mesh, EncodeOptions{});
  ASSERT_TRUE(bytes);
  auto index = read_stream_index(*bytes);
  ASSERT_TRUE(index);
  EXPECT_EQ(index->header.extra.at(0), kRefinementFormat);
  EXPECT_EQ(kRefinementFormat, 3);
  for (int format : {1, 4, 255}) {
    EncodeOptions options;
    options.refinement_format = static_cast<RefinementFormat>(format);
    auto refused = encode_hcs(mesh, options);
    ASSERT_FALSE(refused) << format;
    EXPECT_EQ(refused.error().code, ErrorCode::kInvalidArgument);
  }
}

// Random skewed bits through FastStartBitModel and BitModel trees round-trip, and
// FastStartBitModel adapts as documented: 1/4 of the error for the first two bits,
// then 1/8, 1/16, and 1/32 (BitModel's rate) from the 14th bit on.
TEST(RefinementFormat, BitModelVRoundTripsAndFollowsItsSchedule) {
  EXPECT_EQ(fast_start_rate(0), 2u);
  EXPECT_EQ(fast_start_rate(1), 2u);
  EXPECT_EQ(fast_start_rate(2), 3u);
  EXPECT_EQ(fast_start_rate(5), 3u);
  EXPECT_EQ(fast_start_rate(6), 4u);
  EXPECT_EQ(fast_start_rate(13), 4u);
  EXPECT_EQ(fast_start_rate(14), 5u);
  FastStartBitModel m;
  m.state = fast_start_next(m.state, 0);
  EXPECT_EQ(m.state & 2047u, 1024u + 256u);
  EXPECT_EQ(m.state >> kFastStartSeenShift, 1u);
  for (int i = 0; i < 40; ++i) m.state = fast_start_next(m.state, 1);
  EXPECT_EQ(m.state >> kFastStartSeenShift, kFastStartSeenMax);
  EXPECT_GT(m.state & 2047u, 0u);
  EXPECT_LT(m.state & 2047u, 200u);

  std::mt19937 rng(7);
  std::vector<uint32_t> symbols(5000);
  for (uint32_t& s : symbols)
    s = std::min<uint32_t>(15, std::geometric_distribution<uint32_t>(0.4)(rng));
  RangeEncoder enc;
  BitTreeModel<4, FastStartBitModel> tree_v[3];
  BitTreeModel<4> tree[3];
  FastStartIntModel ints;
  for (size_t i = 0; i < symbols.size(); ++i) {
    tree_v[i % 3].encode(enc, symbols[i]);
    tree[i % 3].encode(enc, symbols[i]);
    ints.encode(enc, int32_t(symbols[i]) * (i % 2 ? -37 : 11));
  }
  const std::vector<uint8_t> bytes = enc.finish();
  RangeDecoder dec(bytes);
  BitTreeModel<4, FastStartBitModel> dtree_v[3];
  BitTreeModel<4> dtree[3];
  FastStartIntModel dints;
  for (size_t i = 0; i < symbols.size(); ++i) {
    ASSERT_EQ(dtree_v[i % 3].decode(dec), symbols[i]) << i;
    ASSERT_EQ(dtree[i % 3].decode(dec), symbols[i]) << i;
    ASSERT_EQ(dints.decode(dec), int64_t(symbols[i]) * (i % 2 ? -37 : 11)) << i;
  }
  EXPECT_FALSE(dec.exhausted_badly());
}

// The decoder's valence limit is the format's (stream_format.h), no longer
// decimate.h's; the encoder must stay within it or its streams would not
// decode.
static_assert(kMaxRemovalValence <= kMaxInsertedValence,
              "the encoder would remove vertices the decoder cannot insert");

}  // namespace
}  // namespace meshstream
