#include "common/codec/range_coder.h"

#include <gtest/gtest.h>

#include <random>

namespace meshstream {
namespace {

TEST(RangeCoder, BitsAndIntegersRoundTrip) {
  std::mt19937 rng(7);
  std::vector<uint32_t> bits;
  std::vector<int32_t> ints;
  std::vector<uint32_t> direct;
  RangeEncoder enc;
  BitModel bm[4];
  AdaptiveIntModel im;
  BitTreeModel<3> tree;
  std::vector<uint32_t> tree_values;
  for (int i = 0; i < 20000; ++i) {
    uint32_t b = (rng() % 10) < 2;
    bits.push_back(b);
    enc.encode_bit(bm[i & 3], b);
    int32_t v = static_cast<int32_t>(rng() % 2001) - 1000;
    if (i % 97 == 0) v = static_cast<int32_t>(rng());  // huge values too
    if (i % 101 == 0) v = INT32_MIN + 1;
    ints.push_back(v);
    im.encode(enc, v);
    uint32_t d = rng() & 0xFFFF;
    direct.push_back(d);
    enc.encode_direct(d, 16);
    uint32_t t = rng() % 8;
    tree_values.push_back(t);
    tree.encode(enc, t);
  }
  std::vector<uint8_t> bytes = enc.finish();
  RangeDecoder dec(bytes);
  BitModel dm[4];
  AdaptiveIntModel dim;
  BitTreeModel<3> dtree;
  for (int i = 0; i < 20000; ++i) {
    ASSERT_EQ(dec.decode_bit(dm[i & 3]), bits[i]) << i;
    ASSERT_EQ(dim.decode(dec), ints[i]) << i;
    ASSERT_EQ(dec.decode_direct(16), direct[i]) << i;
    ASSERT_EQ(dtree.decode(dec), tree_values[i]) << i;
  }
  EXPECT_FALSE(dec.exhausted_badly());
}

TEST(RangeCoder, SkewedBitsCompress) {
  RangeEncoder enc;
  BitModel m;
  for (int i = 0; i < 80000; ++i) enc.encode_bit(m, i % 50 == 0);
  // H(0.02) ~ 0.14 bits: 80000 bits -> about 1.4 KB; allow adaptation slack.
  EXPECT_LT(enc.finish().size(), 2000u);
}

TEST(RangeCoder, GarbageNeverReadsOutOfBounds) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<uint8_t> junk(rng() % 40);
    for (auto& b : junk) b = static_cast<uint8_t>(rng());
    RangeDecoder dec(junk);
    AdaptiveIntModel m;
    for (int i = 0; i < 2000; ++i) (void)m.decode(dec);
    if (junk.size() < 20) {
      EXPECT_TRUE(dec.exhausted_badly());
    }
  }
}

}  // namespace
}  // namespace meshstream
