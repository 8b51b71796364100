// The varint and integer helpers of byte_io.h, and the one reader of the
// layout that once had its own varint: reseal_checksums.
#include "common/codec/byte_io.h"

#include <gtest/gtest.h>

#include "common/codec/container.h"
#include "common/codec/container_reseal.h"
#include "common/codec/crc32.h"

namespace meshstream {
namespace {

TEST(ByteIo, VarintsRoundTripAtEveryLength) {
  for (uint32_t v : {0u, 1u, 127u, 128u, 16383u, 16384u, (1u << 28) - 1, 1u << 28, UINT32_MAX}) {
    std::vector<uint8_t> bytes;
    put_varint(bytes, v);
    size_t pos = 0;
    uint32_t back = 0;
    ASSERT_TRUE(get_varint(bytes, pos, back)) << v;
    EXPECT_EQ(back, v);
    EXPECT_EQ(pos, bytes.size());
  }
}

TEST(ByteIo, VarintRefusesValuesBeyond32BitsAndCutShortOnes) {
  // UINT32_MAX is FF FF FF FF 0F; a fifth byte with any of bits 4-6 set
  // means a value of 2^32 or more.
  const std::vector<uint8_t> too_big = {0x85, 0x80, 0x80, 0x80, 0x10};
  size_t pos = 0;
  uint32_t v = 0;
  EXPECT_FALSE(get_varint(too_big, pos, v));
  const std::vector<uint8_t> six_bytes = {0x80, 0x80, 0x80, 0x80, 0x80, 0x00};
  pos = 0;
  EXPECT_FALSE(get_varint(six_bytes, pos, v));
  const std::vector<uint8_t> cut = {0x80, 0x80};
  pos = 0;
  EXPECT_FALSE(get_varint(cut, pos, v));
}

TEST(ByteIo, LittleEndianIntegers) {
  std::vector<uint8_t> b;
  put_u16(b, 0x1234);
  put_u32(b, 0xA1B2C3D4u);
  put_f32(b, -2.5f);
  ASSERT_EQ(b.size(), 10u);
  EXPECT_EQ(b[0], 0x34);
  EXPECT_EQ(b[2], 0xD4);
  EXPECT_EQ(get_u16(b.data()), 0x1234);
  EXPECT_EQ(get_u32(b.data() + 2), 0xA1B2C3D4u);
  EXPECT_EQ(get_f32(b.data() + 6), -2.5f);
  set_u32(b.data() + 2, 7);
  EXPECT_EQ(get_u32(b.data() + 2), 7u);
  std::vector<uint8_t> w;
  put_u32(w, 0x01020304u);
  put_u32(w, 0x05060708u);
  EXPECT_EQ(get_u64(w.data()), 0x0506070801020304ull);
}

// A version-2 stream whose first index entry codes its size 5 as an
// overlong varint of 2^32 + 5 (low 32 bits: 5). The reader refuses the
// entry; reseal_checksums must read it the same way and leave the entry's
// CRC and everything after it alone. A reseal whose varint drops the bits
// beyond 32 read it as 5 and sealed both records' CRCs.
TEST(ByteIo, ResealRefusesAVarintBeyond32BitsAsTheReaderDoes) {
  StreamHeader header;
  header.vertex_count = 20;
  header.face_count = 36;
  header.base_vertex_count = 10;
  header.base_face_count = 16;
  header.bounds = {{0, 0, 0}, {1, 1, 1}};
  header.layer_count = 1;
  const std::vector<std::vector<uint8_t>> payloads = {{1, 2, 3, 4, 5}, {6, 7, 8}};
  std::vector<RecordEntry> records(2);
  records[0] = {0, 5, 10, 16, 0, false};  // CRCs left 0: reseal fills them
  records[1] = {0, 3, 20, 36, 0, false};
  std::vector<uint8_t> s = write_container_prefix(header, records);
  const size_t count_at = 12 + get_u32(s.data() + 8) + 4;
  const size_t entries_at = count_at + 8;
  ASSERT_EQ(s[entries_at], 5);  // entry 0's size, one byte
  const std::vector<uint8_t> overlong = {0x85, 0x80, 0x80, 0x80, 0x10};
  s.erase(s.begin() + entries_at);
  s.insert(s.begin() + entries_at, overlong.begin(), overlong.end());
  set_u32(s.data() + count_at + 4, get_u32(s.data() + count_at + 4) + 4);
  for (const auto& p : payloads) s.insert(s.end(), p.begin(), p.end());
  // Entry 0: 5 size bytes, dv, gap, then its CRC.
  const size_t crc0_at = entries_at + overlong.size() + 2;
  const size_t crc1_at = crc0_at + 4 + 3;
  ASSERT_EQ(get_u32(s.data() + crc0_at), 0u);

  reseal_checksums(s);
  EXPECT_EQ(get_u32(s.data() + crc0_at), 0u) << "entry 0 was sealed as if its size fit 32 bits";
  EXPECT_EQ(get_u32(s.data() + crc1_at), 0u);
  // The header and index CRCs are resealed, so what the reader refuses is
  // the entry itself.
  auto index = read_stream_index(s);
  ASSERT_FALSE(index);
  EXPECT_EQ(index.error().code, ErrorCode::kParse);
  EXPECT_NE(index.error().message.find("entry 0"), std::string::npos) << index.error().message;
}

}  // namespace
}  // namespace meshstream
