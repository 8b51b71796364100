// RangeDecoder renormalizes with one byte shift per bit (normalize()), which
// is exact only while every model's probability stays within [31, 2017] /
// 2048 (then a range >= 2^24 before a bit is > 2^16 after it). These tests
// hold the models to that bound under the most skewed inputs and check that
// such runs, where the range shrinks fastest, still decode exactly.
#include <gtest/gtest.h>

#include <random>

#include "common/codec/range_coder.h"

namespace meshstream {
namespace {

constexpr uint32_t kMinP = 31, kMaxP = 2017;

template <class Model>
uint32_t probability(const Model& m) {
  if constexpr (std::is_same_v<Model, BitModel>) {
    return m.p;
  } else {
    return m.state & 2047u;
  }
}

// Bit sequences that push a model to its extremes: long runs of one value,
// runs after a run of the other, alternation and random skewed bits.
std::vector<std::vector<uint32_t>> skewed_sequences() {
  std::vector<std::vector<uint32_t>> out;
  out.push_back(std::vector<uint32_t>(5000, 0));
  out.push_back(std::vector<uint32_t>(5000, 1));
  std::vector<uint32_t> flip(5000, 0);
  for (size_t i = 2500; i < flip.size(); ++i) flip[i] = 1;
  out.push_back(flip);
  std::vector<uint32_t> alternate(5000);
  for (size_t i = 0; i < alternate.size(); ++i) alternate[i] = i & 1;
  out.push_back(alternate);
  std::mt19937 rng(11);
  for (uint32_t percent : {1u, 50u, 99u}) {
    std::vector<uint32_t> r(5000);
    for (auto& b : r) b = rng() % 100 < percent ? 1 : 0;
    out.push_back(r);
  }
  return out;
}

template <class Model>
void check_bound_and_round_trip() {
  for (const auto& bits : skewed_sequences()) {
    Model em;
    RangeEncoder enc;
    for (uint32_t b : bits) {
      enc.encode_bit(em, b);
      ASSERT_GE(probability(em), kMinP);
      ASSERT_LE(probability(em), kMaxP);
    }
    // Direct bits in between: they halve the range.
    enc.encode_direct(0x5A5A5, 20);
    const std::vector<uint8_t> bytes = enc.finish();
    RangeDecoder dec(bytes);
    Model dm;
    for (size_t i = 0; i < bits.size(); ++i) ASSERT_EQ(dec.decode_bit(dm), bits[i]) << "bit " << i;
    EXPECT_EQ(dec.decode_direct(20), 0x5A5A5u);
    EXPECT_FALSE(dec.exhausted_badly());
  }
}

TEST(RangeDecoderNormalize, BitModelStaysInBoundAndDecodes) {
  check_bound_and_round_trip<BitModel>();
}

TEST(RangeDecoderNormalize, BitModelVStaysInBoundAndDecodes) {
  check_bound_and_round_trip<FastStartBitModel>();
}

// Every state a FastStartBitModel can reach from its start, by exhaustive search
// over the (probability, count) pairs: the bound holds for all of them.
TEST(RangeDecoderNormalize, EveryReachableBitModelVStateIsInBound) {
  std::vector<uint8_t> seen(1u << 16, 0);
  std::vector<uint16_t> todo = {FastStartBitModel{}.state};
  seen[todo[0]] = 1;
  size_t reached = 0;
  while (!todo.empty()) {
    const uint16_t s = todo.back();
    todo.pop_back();
    ++reached;
    ASSERT_GE(s & 2047u, kMinP) << "state " << s;
    ASSERT_LE(s & 2047u, kMaxP) << "state " << s;
    for (uint16_t next : {fast_start_after0(s), fast_start_after1(s)}) {
      if (!seen[next]) {
        seen[next] = 1;
        todo.push_back(next);
      }
    }
  }
  EXPECT_GT(reached, 1000u);
}

}  // namespace
}  // namespace meshstream
