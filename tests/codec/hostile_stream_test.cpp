// Truncated, bit-flipped, re-checksummed and random streams: errors, never
// crashes, and the decoder keeps the last good mesh.
#include <random>

#include <gtest/gtest.h>

#include "common/codec/crc32.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/adjacency.h"
#include "tests/codec/codec_test_util.h"

namespace meshstream {
namespace {

using namespace meshstream::testing;

std::vector<uint8_t> sample_stream(bool draco_base = true) {
  EncodeOptions opt;
  opt.target_base_vertices = 30;
  opt.record_bytes = 120;
  opt.allow_draco_base = draco_base;
  auto bytes = encode_hcs(combine({icosphere(3, 0.2f), height_field(12, 9), torus(16, 10)}), opt);
  EXPECT_TRUE(bytes);
  return *bytes;
}

// The mesh after exactly `records` records of a clean stream.
Mesh mesh_after(const std::vector<uint8_t>& clean, uint32_t records) {
  IncrementalDecoder dec;
  auto index = read_stream_index(clean);
  const uint64_t end = records == 0 ? index->payload_offset
                                    : index->records[records - 1].offset + index->records[records - 1].size;
  EXPECT_TRUE(dec.feed(std::span<const uint8_t>(clean.data(), end)));
  return dec.mesh();
}

TEST(HostileStream, TruncatedPrefixesDecodeWhatIsComplete) {
  const std::vector<uint8_t> clean = sample_stream();
  auto index = read_stream_index(clean);
  ASSERT_TRUE(index);
  std::mt19937 rng(11);
  for (int trial = 0; trial < 60; ++trial) {
    const size_t cut = rng() % clean.size();
    IncrementalDecoder dec;
    auto r = dec.feed(std::span<const uint8_t>(clean.data(), cut));
    ASSERT_TRUE(r) << "a truncated stream is not an error while more may come: " << r.error().message;
    EXPECT_FALSE(dec.finished());
    auto whole = decode_hcs(std::span<const uint8_t>(clean.data(), cut));
    if (cut < index->records[0].offset + index->records[0].size) {
      ASSERT_FALSE(whole);
      EXPECT_EQ(whole.error().code, ErrorCode::kTruncated);
    } else {
      ASSERT_TRUE(whole);
      EXPECT_EQ(whole->triangles, mesh_after(clean, dec.records_decoded()).triangles);
    }
  }
}

TEST(HostileStream, EveryBitFlipIsDetectedAndKeepsTheLastGoodMesh) {
  for (bool draco : {true, false}) {
    const std::vector<uint8_t> clean = sample_stream(draco);
    std::mt19937 rng(5);
    for (int trial = 0; trial < 300; ++trial) {
      std::vector<uint8_t> bad = clean;
      const size_t at = rng() % bad.size();
      bad[at] ^= uint8_t(1u << (rng() % 8));
      IncrementalDecoder dec;
      auto r = dec.feed(bad);
      if (r) {
        // A flip in the record count makes the index look longer than the
        // bytes so far: the decoder waits for more, having applied nothing.
        ASSERT_EQ(dec.index(), nullptr) << "flip at byte " << at << " went unnoticed";
        ASSERT_EQ(dec.records_decoded(), 0u);
        continue;
      }
      EXPECT_FALSE(r.error().message.empty());
      // The mesh is the one of the records before the damaged one.
      const Mesh expect = mesh_after(clean, dec.records_decoded());
      EXPECT_EQ(dec.mesh().triangles, expect.triangles);
      EXPECT_EQ(dec.mesh().positions, expect.positions);
      // Errors are sticky.
      EXPECT_FALSE(dec.feed(std::span<const uint8_t>(clean.data(), 1)));
    }
  }
}

// Damaged payloads with valid checksums reach the record decoders
// themselves: every range check is exercised. The result is either an error
// with the last good mesh kept, or a valid manifold mesh.
TEST(HostileStream, ResealedCorruptionNeverBreaksTheMesh) {
  const std::vector<uint8_t> clean = sample_stream();
  auto index = read_stream_index(clean);
  ASSERT_TRUE(index);
  std::mt19937 rng(9);
  int errors = 0;
  for (int trial = 0; trial < 400; ++trial) {
    std::vector<RecordEntry> entries = index->records;
    std::vector<std::vector<uint8_t>> payloads;
    for (const RecordEntry& e : entries)
      payloads.emplace_back(clean.begin() + e.offset, clean.begin() + e.offset + e.size);
    const size_t victim = rng() % entries.size();
    std::vector<uint8_t>& p = payloads[victim];
    const int flips = 1 + rng() % 4;
    for (int f = 0; f < flips && !p.empty(); ++f) {
      if (rng() % 8 == 0) {
        p.resize(rng() % (p.size() + 1));  // cut short
      } else {
        p[rng() % p.size()] ^= uint8_t(1u << (rng() % 8));
      }
    }
    entries[victim].size = static_cast<uint32_t>(p.size());
    entries[victim].crc32 = crc32(0, p.data(), p.size());
    std::vector<uint8_t> stream = write_container_prefix(index->header, entries);
    for (auto& q : payloads) stream.insert(stream.end(), q.begin(), q.end());

    IncrementalDecoder dec;
    auto r = dec.feed(stream);
    if (!r) {
      ++errors;
      // Damage that still decodes yields a different (valid) mesh, and a
      // later record may then fail; before the victim all is as clean.
      if (dec.records_decoded() > 0 && dec.records_decoded() <= victim) {
        const Mesh expect = mesh_after(clean, dec.records_decoded());
        EXPECT_EQ(dec.mesh().triangles, expect.triangles);
        EXPECT_EQ(dec.mesh().positions, expect.positions);
      }
    }
    if (dec.records_decoded() > 0) {
      auto adj = Adjacency::build(dec.mesh());
      EXPECT_TRUE(adj) << "trial " << trial << ": " << adj.error().message;
    }
  }
  EXPECT_GT(errors, 200);  // most damage is caught by the range checks
}

TEST(HostileStream, RandomBytesAreRefused) {
  std::mt19937 rng(13);
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<uint8_t> junk(rng() % 600);
    for (auto& b : junk) b = static_cast<uint8_t>(rng());
    if (trial % 2 == 0 && junk.size() >= 4) std::copy(kContainerMagic, kContainerMagic + 4, junk.begin());
    IncrementalDecoder dec;
    auto r = dec.feed(junk);
    if (r) {
      EXPECT_EQ(*r, 0u);  // at best "need more bytes"
      EXPECT_EQ(dec.records_decoded(), 0u);
    }
    EXPECT_FALSE(decode_hcs(junk));
  }
}

}  // namespace
}  // namespace meshstream
