// Truncated, bit-flipped, re-checksummed and random streams: errors, never
// crashes, and the decoder keeps the last good mesh.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <iterator>
#include <random>

#include "common/codec/base_coder.h"
#include "common/codec/byte_io.h"
#include "common/codec/container_reseal.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/codec/quantize.h"
#include "common/codec/refinement_codec.h"
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

// The record payloads of a stream (without version-3 trailers).
std::vector<std::vector<uint8_t>> payloads_of(const std::vector<uint8_t>& stream,
                                              const StreamIndex& index) {
  std::vector<std::vector<uint8_t>> payloads;
  for (const RecordEntry& e : index.records) {
    const auto p = record_payload(e, std::span<const uint8_t>(stream).subspan(e.offset, e.size));
    payloads.emplace_back(p.begin(), p.end());
  }
  return payloads;
}

// A stream of `payloads` with the counts of `index` and valid checksums.
std::vector<uint8_t> rebuild(const StreamIndex& index,
                             const std::vector<std::vector<uint8_t>>& payloads) {
  std::vector<RecordCounts> counts;
  for (const RecordEntry& e : index.records) counts.push_back({e.vertices, e.faces});
  auto written = write_container(index.header, payloads, counts);
  EXPECT_TRUE(written) << written.error().message;
  return written ? written->bytes : std::vector<uint8_t>{};
}

// The mesh after exactly `records` records of a clean stream.
Mesh mesh_after(const std::vector<uint8_t>& clean, uint32_t records) {
  IncrementalDecoder dec;
  auto index = read_stream_index(clean);
  const uint64_t end = records == 0
                           ? index->payload_offset
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
    ASSERT_TRUE(r) << "a truncated stream is not an error while more may come: "
                   << r.error().message;
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
    std::vector<std::vector<uint8_t>> payloads = payloads_of(clean, *index);
    const size_t victim = rng() % payloads.size();
    std::vector<uint8_t>& p = payloads[victim];
    const int flips = 1 + rng() % 4;
    for (int f = 0; f < flips && !p.empty(); ++f) {
      if (rng() % 8 == 0) {
        p.resize(rng() % (p.size() + 1));  // cut short
      } else {
        p[rng() % p.size()] ^= uint8_t(1u << (rng() % 8));
      }
    }
    const std::vector<uint8_t> stream = rebuild(*index, payloads);

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
    if (trial % 2 == 0 && junk.size() >= 4)
      std::copy(kContainerMagic, kContainerMagic + 4, junk.begin());
    IncrementalDecoder dec;
    auto r = dec.feed(junk);
    if (r) {
      EXPECT_EQ(*r, 0u);  // at best "need more bytes"
      EXPECT_EQ(dec.records_decoded(), 0u);
    }
    EXPECT_FALSE(decode_hcs(junk));
  }
}

// Plane records (embedded geometry) damaged with valid checksums: an error
// with the last good mesh kept, or a valid mesh; never a vertex off the grid.
TEST(HostileStream, ResealedPlaneRecordCorruption) {
  const std::vector<uint8_t> clean = sample_stream();
  auto index = read_stream_index(clean);
  ASSERT_TRUE(index);
  std::vector<size_t> planes;
  for (size_t i = 1; i < index->records.size(); ++i)
    if (clean[index->records[i].offset] == kRecordPlane) planes.push_back(i);
  // How many depends on the encoder's record order (format 3's stream has
  // 2, format 2's had more); two are victims enough for 300 trials.
  ASSERT_GE(planes.size(), 2u) << "the sample stream has plane records";
  std::mt19937 rng(21);
  int errors = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<std::vector<uint8_t>> payloads = payloads_of(clean, *index);
    const size_t victim = planes[rng() % planes.size()];
    std::vector<uint8_t>& p = payloads[victim];
    switch (trial % 4) {
      case 0:
        p.resize(1 + rng() % p.size());
        break;  // cut short
      case 1:
        p[1 + rng() % 3 % (p.size() - 1)] ^= uint8_t(1u << (rng() % 8));
        break;  // range header
      default:
        p[rng() % p.size()] ^= uint8_t(1u << (rng() % 8));
        break;
    }
    const std::vector<uint8_t> stream = rebuild(*index, payloads);
    IncrementalDecoder dec;
    auto r = dec.feed(stream);
    if (!r) {
      ++errors;
      if (dec.records_decoded() <= victim) {
        const Mesh expect = mesh_after(clean, dec.records_decoded());
        EXPECT_EQ(dec.mesh().positions, expect.positions);
      }
    }
    // The grid spans the box's largest extent on every axis.
    const BoundingBox box = index->header.bounds;
    const float extent =
        std::max({box.max.x - box.min.x, box.max.y - box.min.y, box.max.z - box.min.z});
    for (const Vec3f& v : dec.mesh().positions) {
      for (int a = 0; a < 3; ++a) {
        const float lo = (&box.min.x)[a], hi = lo + extent;
        const float slack = 1e-4f * (1 + extent);
        EXPECT_GE((&v.x)[a], lo - slack);
        EXPECT_LE((&v.x)[a], hi + slack);
      }
    }
  }
  EXPECT_GT(errors, 20);
}

// A plane record naming vertices the mesh does not have is refused.
TEST(HostileStream, PlaneRecordOutsideTheMeshIsRefused) {
  const std::vector<uint8_t> clean = sample_stream();
  auto index = read_stream_index(clean);
  ASSERT_TRUE(index);
  for (uint32_t first : {0u, 5u, 1u << 20}) {
    std::vector<std::vector<uint8_t>> payloads = payloads_of(clean, *index);
    // Record 1 becomes a plane record over [first, first + 10^6).
    std::vector<uint8_t> p = {kRecordPlane};
    put_varint(p, first);
    put_varint(p, 1000000);
    p.insert(p.end(), 16, 0x55);
    payloads[1] = p;
    const std::vector<uint8_t> stream = rebuild(*index, payloads);
    IncrementalDecoder dec;
    auto r = dec.feed(stream);
    ASSERT_FALSE(r);
    EXPECT_EQ(dec.records_decoded(), 1u);
    EXPECT_NE(r.error().message.find("plane record"), std::string::npos) << r.error().message;
  }
}

// Draco base records are checked before Draco allocates anything: counts
// that differ from the index, or another bitstream version, are refused.
TEST(HostileStream, DracoBaseCountsAreCheckedBeforeDecoding) {
  Mesh m = icosphere(2, 0.1f);
  auto grid = make_grid(m, 12);
  ASSERT_TRUE(grid);
  BaseMesh base;
  base.positions = quantize_positions(m, *grid);
  base.faces = m.triangles;
  auto bytes = encode_base_draco(base);
  ASSERT_TRUE(bytes);
  const uint32_t nv = uint32_t(base.positions.size()), nf = uint32_t(base.faces.size());
  ASSERT_TRUE(decode_base_draco(*bytes, nv, nf, 12));
  auto refused = [](const Result<BaseMesh>& r) {
    return !r && r.error().message.find("refused before decoding") != std::string::npos;
  };
  EXPECT_TRUE(refused(decode_base_draco(*bytes, nv + 1, nf, 12)));
  EXPECT_TRUE(refused(decode_base_draco(*bytes, nv, nf - 2, 12)));
  std::vector<uint8_t> v = *bytes;
  v[5] = 1;  // legacy bitstream version: another parser inside Draco
  EXPECT_TRUE(refused(decode_base_draco(v, nv, nf, 12)));
  // A huge declared face count (varint at byte 14) matching a hostile index.
  std::vector<uint8_t> huge(bytes->begin(), bytes->begin() + 14);
  for (uint8_t b : {0xFF, 0xFF, 0xFF, 0xFF, 0x0F}) huge.push_back(b);
  huge.insert(huge.end(), bytes->begin() + 16, bytes->end());
  EXPECT_TRUE(refused(decode_base_draco(huge, nv, 0xFFFFFFFFu, 12)));
}

// reseal_checksums (for fuzzers) makes a damaged stream pass every CRC check
// of every container version, so the damage reaches the record decoders.
TEST(HostileStream, ResealMakesEveryChecksumMatch) {
  std::vector<uint8_t> stream = sample_stream();
  auto clean = read_stream_index(stream);
  ASSERT_TRUE(clean);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<uint8_t> damaged = stream;
    const RecordEntry& victim = clean->records[1 + rng() % (clean->records.size() - 1)];
    damaged[victim.offset + rng() % victim.size] ^= 0x10;
    reseal_checksums(damaged);
    auto index = read_stream_index(damaged);
    ASSERT_TRUE(index) << index.error().message;
    for (const RecordEntry& r : index->records)
      EXPECT_TRUE(record_intact(r, std::span<const uint8_t>(damaged.data() + r.offset, r.size)));
  }
  // A version-1 stream from issue I's encoder.
  std::ifstream in(
      std::string(MESHSTREAM_SOURCE_DIR) + "/tests/codec/data/issue1_components3_own.hcs",
      std::ios::binary);
  ASSERT_TRUE(in);
  std::vector<uint8_t> v1{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  ASSERT_GT(v1.size(), 6u);
  ASSERT_EQ(v1[4] | v1[5] << 8, 1) << "container version 1";
  auto index = read_stream_index(v1);
  ASSERT_TRUE(index);
  v1[index->records.back().offset] ^= 0x01;
  EXPECT_FALSE(record_intact(index->records.back(),
                             std::span<const uint8_t>(v1.data() + index->records.back().offset,
                                                      index->records.back().size)));
  reseal_checksums(v1);
  auto resealed = read_stream_index(v1);
  ASSERT_TRUE(resealed);
  EXPECT_TRUE(record_intact(resealed->records.back(),
                            std::span<const uint8_t>(v1.data() + resealed->records.back().offset,
                                                     resealed->records.back().size)));
  // Random bytes: never out of bounds (run under the sanitizer builds).
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<uint8_t> junk(rng() % 300);
    for (auto& b : junk) b = uint8_t(rng());
    if (junk.size() >= 8 && trial % 2) {
      std::copy(kContainerMagic, kContainerMagic + 4, junk.begin());
      junk[4] = uint8_t(1 + trial % 3);
      junk[5] = 0;
    }
    reseal_checksums(junk);
  }
}

// The fuzzer's reproducer (tests/fuzz/regressions/hcs_decoder): refused
// quickly, no multi-gigabyte reservation.
TEST(HostileStream, DracoReservationReproducerIsRefusedQuickly) {
  const std::string path = std::string(MESHSTREAM_SOURCE_DIR) +
                           "/tests/fuzz/regressions/hcs_decoder/draco-base-reserves-5.7GB";
  std::ifstream in(path, std::ios::binary);
  ASSERT_TRUE(in) << path;
  const std::vector<uint8_t> bytes{std::istreambuf_iterator<char>(in),
                                   std::istreambuf_iterator<char>()};
  const auto start = std::chrono::steady_clock::now();
  auto r = decode_hcs(bytes);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_FALSE(r);
  EXPECT_LT(seconds, 0.5) << "the Draco guard should refuse it before decoding";
}

}  // namespace
}  // namespace meshstream
