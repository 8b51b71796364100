// The shared framing: round trips, limits refused before allocation, the
// zero-copy chunk head byte-identical to the generated serializer.
#include "proto/framing.h"

#include <gtest/gtest.h>

#include <random>

namespace meshstream::proto {
namespace {

v1::ServerMessage sample_chunk(uint64_t offset, uint32_t records, size_t size) {
  v1::ServerMessage m;
  m.mutable_chunk()->set_offset(offset);
  m.mutable_chunk()->set_records_complete(records);
  m.mutable_chunk()->set_data(std::string(size, 'x'));
  return m;
}

TEST(Framing, RoundTripsManyMessagesFedByteByByte) {
  std::vector<uint8_t> wire;
  for (int i = 0; i < 20; ++i) {
    v1::ClientMessage m;
    m.mutable_stream()->set_model("model" + std::to_string(i));
    m.mutable_stream()->set_resume_offset(uint64_t(i) * 1000003);
    append_frame(m, wire);
  }
  ClientFrameReader reader(kDefaultMaxClientFrameBytes);
  int seen = 0;
  for (uint8_t b : wire) {
    reader.feed(std::span<const uint8_t>(&b, 1));
    while (true) {
      auto m = reader.next();
      ASSERT_TRUE(m.has_value()) << m.error().message;
      if (!*m) break;
      EXPECT_EQ((*m)->stream().model(), "model" + std::to_string(seen));
      EXPECT_EQ((*m)->stream().resume_offset(), uint64_t(seen) * 1000003);
      ++seen;
    }
  }
  EXPECT_EQ(seen, 20);
  EXPECT_EQ(reader.buffered(), 0u);
}

TEST(Framing, RefusesTwoGibLengthPrefixAtOnce) {
  std::vector<uint8_t> wire;
  append_varint(wire, uint64_t(1) << 31);
  FrameSplitter splitter(kDefaultMaxClientFrameBytes);
  splitter.feed(wire);
  auto frame = splitter.next();
  ASSERT_FALSE(frame.has_value());
  EXPECT_EQ(frame.error().code, ErrorCode::kLimit);
  EXPECT_LT(splitter.buffered(), 8u);
  // The error sticks.
  splitter.feed(std::vector<uint8_t>(10, 0));
  EXPECT_FALSE(splitter.next().has_value());
}

TEST(Framing, RefusesOversizedLengthFromPartialPrefix) {
  // Two bytes of a 3-byte varint already say "at least 2^14 + ...".
  FrameSplitter splitter(1000);
  const std::vector<uint8_t> partial{0xff, 0xff};
  splitter.feed(partial);
  auto frame = splitter.next();
  ASSERT_FALSE(frame.has_value());
  EXPECT_EQ(frame.error().code, ErrorCode::kLimit);
}

TEST(Framing, RefusesOverlongVarint) {
  FrameSplitter splitter(kMaxServerFrameBytes);
  const std::vector<uint8_t> wire{0x80, 0x80, 0x80, 0x80, 0x80, 0x01};
  splitter.feed(wire);
  auto frame = splitter.next();
  ASSERT_FALSE(frame.has_value());
  EXPECT_EQ(frame.error().code, ErrorCode::kParse);
}

TEST(Framing, GarbagePayloadIsAParseError) {
  const std::vector<uint8_t> wire{4, 0xff, 0xff, 0xff, 0xff};
  ClientFrameReader reader(kDefaultMaxClientFrameBytes);
  reader.feed(wire);
  auto m = reader.next();
  ASSERT_FALSE(m.has_value());
  EXPECT_EQ(m.error().code, ErrorCode::kParse);
}

TEST(Framing, ZeroLengthFrameIsAnEmptyMessage) {
  const std::vector<uint8_t> wire{0};
  ClientFrameReader reader(kDefaultMaxClientFrameBytes);
  reader.feed(wire);
  auto m = reader.next();
  ASSERT_TRUE(m.has_value());
  ASSERT_TRUE(m->has_value());
  EXPECT_EQ((*m)->body_case(), v1::ClientMessage::BODY_NOT_SET);
}

TEST(Framing, ChunkHeadMatchesGeneratedSerializer) {
  const uint64_t offsets[] = {0, 1, 127, 128, 300000, uint64_t(1) << 40};
  const uint32_t records[] = {0, 1, 200, 1u << 22};
  const size_t sizes[] = {1, 127, 128, 16384, 65536, 1 << 20};
  for (uint64_t offset : offsets) {
    for (uint32_t r : records) {
      for (size_t size : sizes) {
        const v1::ServerMessage m = sample_chunk(offset, r, size);
        const std::vector<uint8_t> expected = encode_frame(m);
        const ChunkFrameHead head = encode_chunk_frame_head(offset, r, size);
        std::vector<uint8_t> got(head.bytes, head.bytes + head.size);
        got.insert(got.end(), size, 'x');
        ASSERT_EQ(got, expected) << offset << " " << r << " " << size;
      }
    }
  }
}

TEST(Framing, RandomBytesNeverCrashTheReader) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<uint8_t> bytes(rng() % 64);
    for (auto& b : bytes) b = uint8_t(rng());
    ServerFrameReader reader(4096);
    reader.feed(bytes);
    for (int i = 0; i < 100; ++i) {
      auto m = reader.next();
      if (!m || !*m) break;
    }
  }
}

}  // namespace
}  // namespace meshstream::proto
