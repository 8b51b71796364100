// Streams of earlier container versions (tests/codec/data) still read and
// decode to exactly the mesh they decoded to when they were written:
//   issue1_*      container 1 (24-byte index entries), refinement format 1;
//   container2_*  container 2 (varint index entries with CRCs), format 2,
//                 written by the encoder just before container 3 (kEncoderVersion 4);
//   container3_v8_* container 3, format 3, kEncoderVersion 8 (the last to
//                 write the own base coder, id 1): an icosphere of 642
//                 vertices, 12 bits, base shift 11, 60 base vertices;
//   container3_v10_* container 3, kEncoderVersion 10 (attributes in two
//                 records: the base's values after the base, every inserted
//                 vertex's in the last record): the attribute tests'
//                 faceted cube (8 x 8 per face: per-corner normals and
//                 texture coordinates with seams, per-vertex colours, three
//                 materials, a TANGENT extra attribute, one PNG texture);
//   container3_v11_* the same cube at kEncoderVersion 11 (four values
//                 records after geometry records): pinned so that a later
//                 format keeps version-11 streams decoding;
//   container3_v12_* the same cube at kEncoderVersion 12 (normals leave the
//                 values records for a normals record coded on the complete
//                 mesh; UV predicted from the geometry);
//   container3_v12_sphere_neighbour_normals.hcs Draco's textured sphere
//                 (SphereWithCircleTexture, Apache-2.0) at kEncoderVersion
//                 12, `meshstream encode --no-asa-guidance`: record 1 codes
//                 the base's normals from the neighbours' normals (layout
//                 flag bit 1), which version 13 no longer writes;
//   container3_v13_* the faceted cube at kEncoderVersion 13 (record 1
//                 without the base's normals, which come in the normals
//                 record from vertex 0);
//   container3_v14_* the faceted cube at kEncoderVersion 14 (record 1's
//                 texture coordinates on an 8-bit grid, their low bits in
//                 a low-bits record before the first values record);
//   container3_v14_sphere_low_bits_last.hcs Draco's textured sphere at
//                 kEncoderVersion 14, `meshstream encode --no-asa-guidance`:
//                 every vertex in the base, no values record, so the
//                 low-bits record follows the last geometry record;
//   container3_v15_pos_color_coarse_base.hcs Draco's test_pos_color.ply
//                 (Apache-2.0) at kEncoderVersion 15, `meshstream encode
//                 --no-asa-guidance --base-color-bits 4`: record 1's colours
//                 on a 4-bit grid (layout flag bit 4 on colours), which a
//                 version-14 decoder refuses;
//   container3_v15_sphere_uv_per_wedge.hcs Draco's textured sphere at
//                 kEncoderVersion 15, default options: every UV wedge's
//                 value coded (3 840 for 729 texture coordinates), which
//                 version 16 codes once per vertex (kWedgeRepeat);
//   container3_v16_smooth_cube_normals_per_wedge.hcs the faceted cube with
//                 face charts and smooth normals (attribute_codec_test's
//                 smooth_cube_with_face_charts(6)) at kEncoderVersion 16,
//                 default options: each normal coded once per wedge, which
//                 version 17 codes once per vertex.
// The hashes were recorded with the decoder of that time (its output files
// compared byte for byte with this one's).
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "common/codec/attribute_codec.h"
#include "common/codec/byte_io.h"
#include "common/codec/container.h"
#include "common/codec/container_reseal.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "tests/codec/attribute_test_util.h"
#include "tests/codec/stream_samples.h"

namespace meshstream {
namespace {

using testing::read_sample;

// Positions bit for bit (encoder.h's position_hash) and the face list.
uint64_t mesh_hash(const Mesh& m) {
  uint64_t h = position_hash(m.positions);
  for (const Triangle& t : m.triangles) {
    for (uint32_t v : t) {
      h ^= v;
      h *= 1099511628211ull;
    }
  }
  return h;
}

struct Sample {
  const char* name;
  uint16_t version;
  uint64_t hash;  // of the fully decoded mesh
};

constexpr Sample kSamples[] = {
    {"issue1_components3_draco.hcs", 1, 0x1c0173ae342fb2e7ull},
    {"issue1_components3_own.hcs", 1, 0x1a7a7ca9909ffb7full},
    {"issue1_grid8_draco.hcs", 1, 0xc764fd66f5903d2dull},
    {"container2_components3_draco.hcs", 2, 0x1cb9f4ec02e7977bull},
    {"container2_grid8_own.hcs", 2, 0xd1a914466f82cc24ull},
    {"container3_v8_icosphere3_own.hcs", 3, 0xe37db249c3d62426ull},
};

TEST(LegacyStreams, DecodeToTheSameMeshAsWhenWritten) {
  for (const Sample& s : kSamples) {
    std::vector<uint8_t> bytes = read_sample(s.name);
    auto index = read_stream_index(bytes);
    ASSERT_TRUE(index) << s.name << ": " << index.error().message;
    EXPECT_EQ(index->version, s.version) << s.name;
    // The issue I files carry the fuzz corpus's 16 split bytes after the stream.
    ASSERT_LE(index->total_bytes(), bytes.size()) << s.name;
    bytes.resize(index->total_bytes());
    for (const RecordEntry& r : index->records) {
      EXPECT_TRUE(record_intact(r, std::span<const uint8_t>(bytes).subspan(r.offset, r.size)));
      if (s.version >= 3) continue;  // container 3: a CRC-32 trailer in each record
      EXPECT_FALSE(r.crc_trailer);
      EXPECT_EQ(record_payload(r, std::span<const uint8_t>(bytes).subspan(r.offset, r.size)).size(),
                r.size);
    }
    // Record by record, as a client receives it.
    IncrementalDecoder dec;
    for (const RecordEntry& r : index->records) {
      const uint64_t from = r.offset == index->payload_offset ? 0 : r.offset;
      auto fed = dec.feed(std::span<const uint8_t>(bytes).subspan(from, r.offset + r.size - from));
      ASSERT_TRUE(fed) << s.name << ": " << fed.error().message;
      EXPECT_EQ(dec.mesh().vertex_count(), r.vertices) << s.name;
      EXPECT_EQ(dec.mesh().face_count(), r.faces) << s.name;
    }
    EXPECT_TRUE(dec.finished()) << s.name;
    EXPECT_EQ(mesh_hash(dec.mesh()), s.hash)
        << s.name << " hash 0x" << std::hex << mesh_hash(dec.mesh());
    auto whole = decode_hcs(bytes);
    ASSERT_TRUE(whole) << s.name;
    EXPECT_EQ(mesh_hash(*whole), s.hash) << s.name;
  }
}

// Damage in a version-2 record is caught by the index CRC; reseal makes it
// pass again (the fuzzer's path for old streams).
TEST(LegacyStreams, VersionTwoChecksumsAndReseal) {
  std::vector<uint8_t> bytes = read_sample("container2_grid8_own.hcs");
  auto index = read_stream_index(bytes);
  ASSERT_TRUE(index);
  const RecordEntry victim = index->records[3];
  bytes[victim.offset + victim.size / 2] ^= 0x08;
  EXPECT_FALSE(
      record_intact(victim, std::span<const uint8_t>(bytes).subspan(victim.offset, victim.size)));
  IncrementalDecoder dec;
  auto fed = dec.feed(bytes);
  ASSERT_FALSE(fed);
  EXPECT_EQ(fed.error().code, ErrorCode::kCorrupt);
  EXPECT_EQ(dec.records_decoded(), 3u);
  reseal_checksums(bytes);
  auto resealed = read_stream_index(bytes);
  ASSERT_TRUE(resealed);
  EXPECT_TRUE(record_intact(resealed->records[3],
                            std::span<const uint8_t>(bytes).subspan(victim.offset, victim.size)));
}

// Every face's corner data (positions, normals, texture coordinates,
// colours, material, extra attribute bytes; attribute_test_util.h), hashed.
uint64_t attribute_hash(const Mesh& m) {
  uint64_t h = 1469598103934665603ull;
  for (const auto& face : testing::faces_of(m)) {
    for (const testing::Corner& corner : face) {
      for (float f : corner) {
        uint32_t b;
        std::memcpy(&b, &f, 4);
        h ^= b;
        h *= 1099511628211ull;
      }
    }
  }
  return h;
}

// A stream with attributes of an earlier encoder decodes, record by record
// and at once, to the mesh (attributes, materials and texture bytes
// included) it decoded to when written.
void expect_attributes_decode_as_when_written(const char* sample, uint64_t hash,
                                              size_t middle_records) {
  const std::vector<uint8_t> bytes = read_sample(sample);
  auto index = read_stream_index(bytes);
  ASSERT_TRUE(index) << index.error().message;
  IncrementalDecoder dec;
  size_t attribute_records = 0;
  for (const RecordEntry& r : index->records) {
    const uint64_t from = r.offset == index->payload_offset ? 0 : r.offset;
    auto fed = dec.feed(std::span<const uint8_t>(bytes).subspan(from, r.offset + r.size - from));
    ASSERT_TRUE(fed) << fed.error().message;
    ASSERT_TRUE(check_attribute_counts(dec.mesh()));
    const auto payload = record_payload(r, {bytes.data() + r.offset, r.size});
    attribute_records += !payload.empty() && payload[0] == kRecordAttributes;
  }
  ASSERT_TRUE(dec.finished());
  EXPECT_EQ(attribute_records, middle_records + 2) << "base, values (and normals) records, final";
  EXPECT_EQ(attribute_hash(dec.mesh()), hash)
      << "hash 0x" << std::hex << attribute_hash(dec.mesh());
  auto whole = decode_hcs(bytes);
  ASSERT_TRUE(whole) << whole.error().message;
  EXPECT_EQ(attribute_hash(*whole), hash);
  EXPECT_EQ(whole->materials.size(), 3u);
  ASSERT_EQ(whole->textures.size(), 1u);
  EXPECT_EQ(whole->textures[0].mime_type, "image/png");
  ASSERT_EQ(whole->extra_attributes.size(), 1u);
  EXPECT_EQ(whole->extra_attributes[0].name, "TANGENT");
}

// A stream decodes, record by record (attribute arrays sized at every
// prefix) and at once, to the faces it decoded to when written.
void expect_decodes_as_when_written(const std::vector<uint8_t>& bytes, uint64_t hash,
                                    size_t textures) {
  auto index = read_stream_index(bytes);
  ASSERT_TRUE(index) << index.error().message;
  IncrementalDecoder dec;
  for (const RecordEntry& r : index->records) {
    const uint64_t from = r.offset == index->payload_offset ? 0 : r.offset;
    auto fed = dec.feed(std::span<const uint8_t>(bytes).subspan(from, r.offset + r.size - from));
    ASSERT_TRUE(fed) << fed.error().message;
    ASSERT_TRUE(check_attribute_counts(dec.mesh()));
  }
  ASSERT_TRUE(dec.finished());
  EXPECT_EQ(attribute_hash(dec.mesh()), hash)
      << "hash 0x" << std::hex << attribute_hash(dec.mesh());
  auto whole = decode_hcs(bytes);
  ASSERT_TRUE(whole) << whole.error().message;
  EXPECT_EQ(attribute_hash(*whole), hash);
  EXPECT_EQ(whole->textures.size(), textures);
}

TEST(LegacyStreams, VersionTenAttributesDecodeAsWhenWritten) {
  expect_attributes_decode_as_when_written("container3_v10_faceted_cube_attributes.hcs",
                                           0x52ce8058599d568full, 0);
}

TEST(LegacyStreams, VersionElevenValuesRecordsDecodeAsWhenWritten) {
  expect_attributes_decode_as_when_written("container3_v11_faceted_cube_attributes.hcs",
                                           0x52ce8058599d568full, 4);
}

// Version 12: four values records without normals, then one normals record
// coded on the complete mesh after the last geometry record.
TEST(LegacyStreams, VersionTwelveNormalsRecordsDecodeAsWhenWritten) {
  expect_attributes_decode_as_when_written("container3_v12_faceted_cube_attributes.hcs",
                                           0x52ce8058599d568full, 5);
}

// Version 14: record 1 with coarse texture coordinates, a low-bits record
// before the first of four values records, one normals record.
TEST(LegacyStreams, VersionFourteenCoarseBaseDecodeAsWhenWritten) {
  expect_attributes_decode_as_when_written("container3_v14_faceted_cube_attributes.hcs",
                                           0x52ce8058599d568full, 6);
}

// Version 13: record 1 without normals (layout flag bit 3), four values
// records without normals, one normals record from vertex 0.
TEST(LegacyStreams, VersionThirteenBaseNormalsLateDecodeAsWhenWritten) {
  expect_attributes_decode_as_when_written("container3_v13_faceted_cube_attributes.hcs",
                                           0x52ce8058599d568full, 5);
}

// Version 12's record 1 with the base's normals predicted from the decoded
// neighbours' normals (flag bit 1 on the normals): the decoder keeps that
// prediction for such streams.
TEST(LegacyStreams, VersionTwelveNeighbourNormalsDecodeAsWhenWritten) {
  const std::vector<uint8_t> bytes = read_sample("container3_v12_sphere_neighbour_normals.hcs");
  auto index = read_stream_index(bytes);
  ASSERT_TRUE(index) << index.error().message;
  ASSERT_GT(index->records.size(), 1u);
  const RecordEntry& r1 = index->records[1];
  const auto payload = record_payload(r1, {bytes.data() + r1.offset, r1.size});
  // Layout: varint length, channel count, normals first: kind, flags.
  ASSERT_GE(payload.size(), 6u);
  ASSERT_EQ(payload[0], kRecordAttributes);
  size_t pos = 2;
  uint32_t length = 0;
  ASSERT_TRUE(get_varint(payload, pos, length));
  ASSERT_EQ(payload[pos + 1], uint8_t(AttributeKind::kNormal));
  EXPECT_EQ(payload[pos + 2], 1 | kPredictBaseAlternative);
  expect_decodes_as_when_written(bytes, 0x09209576d7d677d2ull, 1);
}

// Version 14, every vertex in the base: the low-bits record after the last
// geometry record (the decoder keeps record 1's mesh for it).
TEST(LegacyStreams, VersionFourteenLowBitsAfterTheGeometryDecodeAsWhenWritten) {
  const std::vector<uint8_t> bytes = read_sample("container3_v14_sphere_low_bits_last.hcs");
  auto index = read_stream_index(bytes);
  ASSERT_TRUE(index) << index.error().message;
  size_t low = 0, last_geometry = 0;
  for (size_t i = 0; i < index->records.size(); ++i) {
    const RecordEntry& r = index->records[i];
    const auto payload = record_payload(r, {bytes.data() + r.offset, r.size});
    if (payload.size() > 1 && payload[0] == kRecordAttributes &&
        payload[1] == kAttributePartLowBits)
      low = i;
    else if (!payload.empty() && payload[0] != kRecordAttributes && payload[0] != kRecordTexture)
      last_geometry = i;
  }
  EXPECT_GT(low, last_geometry);
  // The same faces as version 12's sphere above: both exact at full rate.
  expect_decodes_as_when_written(bytes, 0x09209576d7d677d2ull, 1);
}

// Version 15: record 1's colours on a 4-bit grid, their low bits later
// (the hash is also what the default stream of the same file decodes to).
TEST(LegacyStreams, VersionFifteenCoarseColoursDecodeAsWhenWritten) {
  expect_decodes_as_when_written(read_sample("container3_v15_pos_color_coarse_base.hcs"),
                                 0x378a6e80e31dc375ull, 0);
}

// Version 15: the sphere's texture coordinates coded per wedge (no
// kWedgeRepeat); the same mesh as the version-14 sphere above.
TEST(LegacyStreams, VersionFifteenUvPerWedgeDecodeAsWhenWritten) {
  expect_decodes_as_when_written(read_sample("container3_v15_sphere_uv_per_wedge.hcs"),
                                 0x09209576d7d677d2ull, 1);
}

// Version 16: texture coordinates with kWedgeRepeat, but a smooth normal
// coded once per wedge where the face charts split its vertex (no
// kWedgeRepeat on the normals): the faceted cube of six segments with face
// charts and smooth normals, default options (attribute_codec_test's
// smooth_cube_with_face_charts). The hash is what the version-16 decoder
// gave (its PLY and GLB output and this decoder's are the same bytes).
TEST(LegacyStreams, VersionSixteenNormalsPerWedgeDecodeAsWhenWritten) {
  expect_decodes_as_when_written(read_sample("container3_v16_smooth_cube_normals_per_wedge.hcs"),
                                 0x7059f6bf8f7a7c19ull, 1);
}

}  // namespace
}  // namespace meshstream
