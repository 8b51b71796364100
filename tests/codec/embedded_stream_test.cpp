// Issue II: the embedded stream. The decoder's mesh at every record boundary
// is the encoder's model bit for bit; plane records only move vertices; the
// granularity bounds hold; budgets pick the right boundary; issue I's
// ordering stays available and exact.
#include <gtest/gtest.h>

#include <algorithm>

#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "tests/codec/codec_test_util.h"

namespace meshstream {
namespace {

using namespace meshstream::testing;

std::vector<Mesh> embedded_meshes() {
  return {icosphere(4, 0.2f), torus(40, 24), height_field(30, 24),
          combine({icosphere(3, 0.1f), tetrahedron(), height_field(8, 5)})};
}

TEST(EmbeddedStream, EveryPrefixEqualsTheEncoderModel) {
  for (const Mesh& mesh : embedded_meshes()) {
    for (bool draco : {true, false}) {
      EncodeOptions options;
      options.allow_draco_base = draco;
      EncodeReport report;
      auto bytes = encode_hcs(mesh, options, &report);
      ASSERT_TRUE(bytes) << bytes.error().message;
      auto index = read_stream_index(*bytes);
      ASSERT_TRUE(index);
      ASSERT_EQ(report.records.size(), index->records.size());
      IncrementalDecoder dec;
      uint64_t fed = 0;
      size_t planes = 0;
      for (size_t i = 0; i < index->records.size(); ++i) {
        const uint64_t end = index->records[i].offset + index->records[i].size;
        auto r = dec.feed(std::span<const uint8_t>(bytes->data() + fed, end - fed));
        fed = end;
        ASSERT_TRUE(r) << "record " << i << ": " << r.error().message;
        ASSERT_EQ(dec.mesh().vertex_count(), report.records[i].vertices) << "record " << i;
        ASSERT_EQ(position_hash(dec.mesh().positions), report.records[i].position_hash)
            << "record " << i << (report.records[i].plane ? " (plane)" : " (structure)");
        if (report.records[i].plane) {
          ++planes;
          ASSERT_EQ(dec.last_deltas().size(), 1u);
          EXPECT_TRUE(dec.last_deltas()[0].added_vertices.empty());
          EXPECT_TRUE(dec.last_deltas()[0].touched_faces.empty());
          EXPECT_FALSE(dec.last_deltas()[0].moved_vertices.empty());
          EXPECT_TRUE(dec.last_deltas()[0].full_rebuild);
        }
      }
      EXPECT_GT(planes, 0u) << "an embedded stream refines positions in plane records";
      auto reference = quantized_reference(mesh, 12);
      ASSERT_TRUE(reference);
      EXPECT_EQ(sorted_positions(dec.mesh()), sorted_positions(*reference));
      EXPECT_EQ(canonical_faces(dec.mesh()), canonical_faces(*reference));
    }
  }
}

}  // namespace
}  // namespace meshstream
