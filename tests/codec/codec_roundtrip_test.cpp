// Exact round trips, valid prefixes, incremental feeding and budgets on
// procedural meshes (real meshes: real_mesh_test.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "common/codec/container_reseal.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/adjacency.h"
#include "tests/codec/codec_test_util.h"

namespace meshstream {
namespace {

using namespace meshstream::testing;

struct Case {
  const char* name;
  Mesh mesh;
};

std::vector<Case> procedural_cases() {
  return {
      {"icosphere3", icosphere(3)},
      {"bumpy_icosphere4", icosphere(4, 0.2f)},
      {"torus", torus(40, 24)},
      {"height_field", height_field(30, 20)},
      {"tetrahedron", tetrahedron()},
      {"components", combine({icosphere(2), tetrahedron(), torus(12, 8), height_field(5, 4)})},
  };
}

void expect_exact(const Mesh& decoded, const Mesh& reference) {
  ASSERT_EQ(decoded.vertex_count(), reference.vertex_count());
  ASSERT_EQ(decoded.face_count(), reference.face_count());
  EXPECT_EQ(sorted_positions(decoded), sorted_positions(reference));
  EXPECT_EQ(canonical_faces(decoded), canonical_faces(reference));
}

void expect_valid(const Mesh& m, const std::string& where) {
  ASSERT_TRUE(validate_arrays(m)) << where;
  auto adj = Adjacency::build(m);
  ASSERT_TRUE(adj) << where << ": " << adj.error().message;
}

class ProceduralRoundTrip : public ::testing::TestWithParam<int> {};

TEST_P(ProceduralRoundTrip, ExactWithBothBaseCoders) {
  Case c = procedural_cases()[GetParam()];
  for (bool draco : {true, false}) {
    EncodeOptions opt;
    opt.target_base_vertices = 20;
    opt.record_bytes = 200;
    opt.allow_draco_base = draco;
    auto bytes = encode_hcs(c.mesh, opt);
    ASSERT_TRUE(bytes) << c.name << ": " << bytes.error().message;
    auto decoded = decode_hcs(*bytes);
    ASSERT_TRUE(decoded) << c.name << ": " << decoded.error().message;
    auto reference = quantized_reference(c.mesh, opt.quant_bits);
    ASSERT_TRUE(reference);
    expect_exact(*decoded, *reference);
  }
}

TEST_P(ProceduralRoundTrip, EveryRecordBoundaryIsAValidMeshWithIndexCounts) {
  Case c = procedural_cases()[GetParam()];
  EncodeOptions opt;
  opt.target_base_vertices = 20;
  opt.record_bytes = 100;
  auto bytes = encode_hcs(c.mesh, opt);
  ASSERT_TRUE(bytes);
  auto index = read_stream_index(*bytes);
  ASSERT_TRUE(index);
  IncrementalDecoder dec;
  uint64_t fed = 0;
  for (size_t i = 0; i < index->records.size(); ++i) {
    const uint64_t end = index->records[i].offset + index->records[i].size;
    auto r = dec.feed(std::span<const uint8_t>(bytes->data() + fed, end - fed));
    fed = end;
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(dec.records_decoded(), i + 1);
    EXPECT_EQ(dec.resume_offset(), end);
    EXPECT_EQ(dec.mesh().vertex_count(), index->records[i].vertices);
    EXPECT_EQ(dec.mesh().face_count(), index->records[i].faces);
    expect_valid(dec.mesh(), std::string(c.name) + " record " + std::to_string(i));
    ASSERT_EQ(dec.last_deltas().size(), 1u);
    if (i > 0) {
      EXPECT_EQ(dec.last_deltas()[0].added_vertices.size(),
                index->records[i].vertices - index->records[i - 1].vertices);
    }
  }
  EXPECT_TRUE(dec.finished());
}

TEST_P(ProceduralRoundTrip, ByteByByteFeedingEqualsOneFeed) {
  Case c = procedural_cases()[GetParam()];
  EncodeOptions opt;
  opt.target_base_vertices = 20;
  opt.record_bytes = 150;
  auto bytes = encode_hcs(c.mesh, opt);
  ASSERT_TRUE(bytes);
  auto whole = decode_hcs(*bytes);
  ASSERT_TRUE(whole);
  IncrementalDecoder dec;
  uint32_t applied = 0;
  for (uint8_t b : *bytes) {
    auto r = dec.feed(std::span<const uint8_t>(&b, 1));
    ASSERT_TRUE(r) << r.error().message;
    applied += *r;
  }
  EXPECT_TRUE(dec.finished());
  EXPECT_EQ(applied, dec.index()->records.size());
  EXPECT_EQ(dec.mesh().positions, whole->positions);
  EXPECT_EQ(dec.mesh().triangles, whole->triangles);
}

// The delta of each record names every face that changed and every vertex
// that was added, so a post-processor can redo only that region.
TEST_P(ProceduralRoundTrip, DeltasCoverEveryChange) {
  Case c = procedural_cases()[GetParam()];
  EncodeOptions opt;
  opt.target_base_vertices = 20;
  opt.record_bytes = 100;
  auto bytes = encode_hcs(c.mesh, opt);
  ASSERT_TRUE(bytes);
  auto index = read_stream_index(*bytes);
  ASSERT_TRUE(index);
  IncrementalDecoder dec;
  uint64_t fed = 0;
  Mesh before;
  for (size_t i = 0; i < index->records.size(); ++i) {
    const uint64_t end = index->records[i].offset + index->records[i].size;
    ASSERT_TRUE(dec.feed(std::span<const uint8_t>(bytes->data() + fed, end - fed)));
    fed = end;
    ASSERT_EQ(dec.last_deltas().size(), 1u);
    const RecordDelta& d = dec.last_deltas()[0];
    EXPECT_EQ(d.record, i);
    const Mesh& after = dec.mesh();
    if (i == 0) {
      EXPECT_TRUE(d.full_rebuild);
    } else {
      // Plane records (moved vertices) flag a full rebuild for consumers
      // that predate moved_vertices; insertions never do.
      EXPECT_EQ(d.full_rebuild, !d.moved_vertices.empty());
      std::vector<uint32_t> touched = d.touched_faces;
      std::sort(touched.begin(), touched.end());
      for (uint32_t f = 0; f < after.face_count(); ++f) {
        const bool changed = f >= before.face_count() || before.triangles[f] != after.triangles[f];
        if (changed) {
          EXPECT_TRUE(std::binary_search(touched.begin(), touched.end(), f)) << "face " << f;
        }
      }
      for (uint32_t f : touched) EXPECT_LT(f, after.face_count());
      ASSERT_EQ(d.added_vertices.size(), after.vertex_count() - before.vertex_count());
      for (size_t j = 0; j < d.added_vertices.size(); ++j)
        EXPECT_EQ(d.added_vertices[j], before.vertex_count() + j);
      // Existing vertices move only in plane records, and only those named.
      std::vector<uint32_t> moved = d.moved_vertices;
      std::sort(moved.begin(), moved.end());
      if (!moved.empty()) {
        EXPECT_TRUE(d.added_vertices.empty());
      }
      for (uint32_t v = 0; v < before.vertex_count(); ++v) {
        if (!(before.positions[v] == after.positions[v])) {
          EXPECT_TRUE(std::binary_search(moved.begin(), moved.end(), v))
              << "vertex " << v << " moved unnamed";
        }
      }
      for (uint32_t v : moved) EXPECT_LT(v, before.vertex_count());
    }
    before = after;
  }
}

INSTANTIATE_TEST_SUITE_P(Meshes, ProceduralRoundTrip, ::testing::Range(0, 6));

TEST(Codec, LayersRemoveAFifthOrMore) {
  Mesh m = icosphere(5, 0.1f);  // 10242 vertices
  EncodeOptions opt;
  auto bytes = encode_hcs(m, opt);
  ASSERT_TRUE(bytes);
  auto index = read_stream_index(*bytes);
  ASSERT_TRUE(index);
  const StreamHeader& h = index->header;
  EXPECT_LE(h.base_vertex_count, 2 * opt.target_base_vertices);
  // log n layers: each keeps at most ~4/5 of the vertices on average.
  const double per_layer =
      std::pow(double(h.base_vertex_count) / h.vertex_count, 1.0 / h.layer_count);
  EXPECT_LT(per_layer, 0.8) << h.layer_count << " layers";
}

// A small stream of many short records (for resume and damage tests).
Result<std::vector<uint8_t>> small_many_record_stream() {
  EncodeOptions opt;
  opt.target_base_vertices = 20;
  opt.record_bytes = 100;
  return encode_hcs(icosphere(3, 0.1f), opt);
}

TEST(Codec, ResumeAtRecordBoundary) {
  auto bytes = small_many_record_stream();
  ASSERT_TRUE(bytes);
  IncrementalDecoder dec;
  const size_t half = bytes->size() / 2;
  ASSERT_TRUE(dec.feed(std::span<const uint8_t>(bytes->data(), half)));
  const uint64_t resume = dec.resume_offset();
  ASSERT_GT(resume, 0u);
  ASSERT_TRUE(dec.resume_at(resume));
  ASSERT_TRUE(dec.feed(std::span<const uint8_t>(bytes->data() + resume, bytes->size() - resume)));
  EXPECT_TRUE(dec.finished());
  auto whole = decode_hcs(*bytes);
  EXPECT_EQ(dec.mesh().triangles, whole->triangles);
  EXPECT_FALSE(dec.resume_at(resume + 1));
}

// A byte altered in transit fails the record's checksum before anything
// is applied: the decoder keeps its last good mesh, says the error is
// recoverable, and after resume_at the good bytes finish the stream exactly.
TEST(Codec, ChecksumFailureIsRecoverableByResuming) {
  auto bytes = small_many_record_stream();
  ASSERT_TRUE(bytes);
  auto index = read_stream_index(*bytes);
  ASSERT_TRUE(index);
  ASSERT_GE(index->records.size(), 4u);
  const RecordEntry& victim = index->records[2];
  std::vector<uint8_t> damaged = *bytes;
  damaged[victim.offset + victim.size / 2] ^= 0x10;

  IncrementalDecoder dec;
  auto fed = dec.feed(damaged);
  ASSERT_FALSE(fed);
  EXPECT_EQ(fed.error().code, ErrorCode::kCorrupt);
  EXPECT_NE(fed.error().message.find("checksum"), std::string::npos) << fed.error().message;
  EXPECT_TRUE(dec.error_is_recoverable());
  EXPECT_EQ(dec.records_decoded(), 2u);
  EXPECT_EQ(dec.resume_offset(), victim.offset);
  EXPECT_FALSE(dec.feed(std::span<const uint8_t>()));  // sticky until resumed

  ASSERT_TRUE(dec.resume_at(dec.resume_offset()));
  const uint64_t from = dec.resume_offset();
  ASSERT_TRUE(dec.feed(std::span<const uint8_t>(bytes->data() + from, bytes->size() - from)));
  EXPECT_TRUE(dec.finished());
  auto whole = decode_hcs(*bytes);
  ASSERT_TRUE(whole);
  EXPECT_EQ(dec.mesh().triangles, whole->triangles);
  EXPECT_EQ(dec.mesh().positions, whole->positions);
}

// A record whose checksum matches but whose content is invalid is the
// stream's own fault: not recoverable, resume_at repeats the error.
TEST(Codec, InvalidRecordWithGoodChecksumStaysFatal) {
  auto bytes = small_many_record_stream();
  ASSERT_TRUE(bytes);
  auto index = read_stream_index(*bytes);
  ASSERT_TRUE(index);
  const RecordEntry& victim = index->records[1];
  // Overwrite the record's content with bytes that decode to nothing valid
  // and make its checksum (and the index's) match them again.
  std::vector<uint8_t> damaged = *bytes;
  std::fill(damaged.begin() + victim.offset, damaged.begin() + victim.offset + victim.size, 0xFF);
  reseal_checksums(damaged);

  IncrementalDecoder dec;
  auto fed = dec.feed(damaged);
  ASSERT_FALSE(fed);
  EXPECT_FALSE(dec.error_is_recoverable()) << fed.error().message;
  EXPECT_FALSE(dec.resume_at(dec.resume_offset()));
}

// kOnRelease keeps no output mesh while decoding and builds it once from
// the decoder's state: at every record boundary that mesh is bit for bit
// the one kEveryRecord keeps record by record, and the decoder is spent
// afterwards.
TEST_P(ProceduralRoundTrip, ReleasedMeshEqualsTheMeshKeptRecordByRecord) {
  Case c = procedural_cases()[GetParam()];
  EncodeOptions opt;
  opt.target_base_vertices = 20;
  opt.record_bytes = 100;
  auto bytes = encode_hcs(c.mesh, opt);
  ASSERT_TRUE(bytes);
  auto index = read_stream_index(*bytes);
  ASSERT_TRUE(index);
  IncrementalDecoder kept;
  uint64_t fed = 0;
  for (size_t i = 0; i < index->records.size(); ++i) {
    const uint64_t end = index->records[i].offset + index->records[i].size;
    ASSERT_TRUE(kept.feed(std::span<const uint8_t>(bytes->data() + fed, end - fed)));
    fed = end;
    IncrementalDecoder once(DecodedMeshUpkeep::kOnRelease);
    ASSERT_TRUE(once.feed(std::span<const uint8_t>(bytes->data(), end)));
    EXPECT_EQ(once.mesh().vertex_count(), 0u);  // nothing kept while decoding
    ASSERT_EQ(once.last_deltas().size(), i + 1);
    for (const RecordDelta& d : once.last_deltas()) {
      // Nothing tracks the changes: no lists, and a consumer told to rebuild.
      EXPECT_TRUE(d.full_rebuild);
      EXPECT_TRUE(d.added_vertices.empty() && d.touched_faces.empty() && d.moved_vertices.empty());
    }
    auto released = once.release_mesh();
    ASSERT_TRUE(released) << released.error().message;
    ASSERT_EQ(released->positions, kept.mesh().positions) << c.name << " record " << i;
    ASSERT_EQ(released->triangles, kept.mesh().triangles) << c.name << " record " << i;
    EXPECT_FALSE(once.release_mesh());
    EXPECT_FALSE(once.feed(std::span<const uint8_t>(bytes->data(), 1)));
  }
  auto moved = kept.release_mesh();
  ASSERT_TRUE(moved);
  auto whole = decode_hcs(*bytes);
  ASSERT_TRUE(whole);
  EXPECT_EQ(moved->positions, whole->positions);
  EXPECT_EQ(moved->triangles, whole->triangles);
}

// kOnRelease has no good mesh once a record failed half-applied, and says
// so; before the base mesh there is none either. A checksum failure, found
// before anything is applied, still leaves the mesh of the records before.
TEST(Codec, ReleaseAfterABadRecordIsAnError) {
  auto bytes = small_many_record_stream();
  ASSERT_TRUE(bytes);
  auto index = read_stream_index(*bytes);
  ASSERT_TRUE(index);
  ASSERT_GE(index->records.size(), 4u);
  {
    IncrementalDecoder dec(DecodedMeshUpkeep::kOnRelease);
    ASSERT_TRUE(dec.feed(std::span<const uint8_t>(bytes->data(), index->payload_offset)));
    auto none = dec.release_mesh();
    ASSERT_FALSE(none);
    EXPECT_EQ(none.error().code, ErrorCode::kTruncated);
  }
  const RecordEntry& victim = index->records[2];
  std::vector<uint8_t> invalid = *bytes;
  std::fill(invalid.begin() + victim.offset, invalid.begin() + victim.offset + victim.size, 0xFF);
  reseal_checksums(invalid);
  {
    IncrementalDecoder dec(DecodedMeshUpkeep::kOnRelease);
    auto fed = dec.feed(invalid);
    ASSERT_FALSE(fed);
    auto released = dec.release_mesh();
    ASSERT_FALSE(released);
    EXPECT_EQ(released.error().message, fed.error().message);
  }
  std::vector<uint8_t> altered = *bytes;
  altered[victim.offset + victim.size / 2] ^= 0x10;
  IncrementalDecoder dec(DecodedMeshUpkeep::kOnRelease);
  ASSERT_FALSE(dec.feed(altered));
  ASSERT_TRUE(dec.error_is_recoverable());
  IncrementalDecoder reference;
  ASSERT_TRUE(reference.feed(std::span<const uint8_t>(bytes->data(), victim.offset)));
  auto released = dec.release_mesh();
  ASSERT_TRUE(released) << released.error().message;
  EXPECT_EQ(released->positions, reference.mesh().positions);
  EXPECT_EQ(released->triangles, reference.mesh().triangles);
}

TEST(Codec, BudgetsSelectTheRightPrefix) {
  Mesh m = icosphere(4, 0.1f);
  EncodeOptions opt;
  opt.target_base_vertices = 50;
  opt.record_bytes = 300;
  auto bytes = encode_hcs(m, opt);
  ASSERT_TRUE(bytes);
  auto index = read_stream_index(*bytes);
  ASSERT_TRUE(index);
  const auto& rec = index->records;
  ASSERT_GT(rec.size(), 4u);
  auto end = [&](size_t i) { return rec[i].offset + rec[i].size; };
  using K = DecodeBudget::Kind;
  EXPECT_EQ(prefix_for_budget(*index, {K::kAll, 0}), bytes->size());
  EXPECT_EQ(prefix_for_budget(*index, {K::kBytes, double(end(3))}), end(3));
  EXPECT_EQ(prefix_for_budget(*index, {K::kBytes, double(end(3) - 1)}), end(2));
  EXPECT_EQ(prefix_for_budget(*index, {K::kBytes, 1}), end(0));  // at least the base
  // Vertex budgets: the last boundary with at most that many vertices (plane
  // records keep the count, so several boundaries may share it).
  auto last_with_at_most = [&](double vertices) {
    uint64_t best = end(0);
    for (size_t i = 0; i < rec.size(); ++i)
      if (rec[i].vertices <= vertices) best = end(i);
    return best;
  };
  EXPECT_EQ(prefix_for_budget(*index, {K::kVertices, double(rec[2].vertices)}),
            last_with_at_most(rec[2].vertices));
  EXPECT_EQ(prefix_for_budget(*index, {K::kVertices, double(rec[2].vertices + 1)}),
            last_with_at_most(rec[2].vertices + 1));
  const double pct = 100.0 * rec[3].vertices / index->header.vertex_count;
  EXPECT_EQ(prefix_for_budget(*index, {K::kPercentVertices, pct}),
            last_with_at_most(rec[3].vertices));
  EXPECT_EQ(prefix_for_budget(*index, {K::kPercentVertices, 100}), bytes->size());
  // Ratio 20: the largest boundary within 1/20 of the stream.
  const uint64_t limit = bytes->size() / 20;
  uint64_t expect = end(0);
  for (size_t i = 0; i < rec.size(); ++i)
    if (end(i) <= limit) expect = end(i);
  EXPECT_EQ(prefix_for_budget(*index, {K::kRatio, 20}), expect);
  EXPECT_EQ(prefix_for_budget(*index, {K::kRatio, 1}), bytes->size());
}

TEST(Codec, RefusesBadInput) {
  Mesh empty;
  EXPECT_FALSE(encode_hcs(empty));
  EncodeOptions opt;
  opt.quant_bits = 7;
  EXPECT_EQ(encode_hcs(icosphere(1), opt).error().code, ErrorCode::kInvalidArgument);
  opt.quant_bits = 21;
  EXPECT_FALSE(encode_hcs(icosphere(1), opt));
  Mesh bad = icosphere(1);
  bad.triangles.push_back(bad.triangles[0]);  // an edge with three faces
  EXPECT_FALSE(encode_hcs(bad));
}

}  // namespace
}  // namespace meshstream
