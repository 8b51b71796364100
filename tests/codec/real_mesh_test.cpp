// Exact round trips and valid prefixes on the real meshes of
// ../shared/meshes (skipped when absent).
#include <gtest/gtest.h>

#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/adjacency.h"
#include "common/mesh/import.h"
#include "tests/codec/codec_test_util.h"
#include "tests/test_meshes.h"

namespace meshstream {
namespace {

using namespace meshstream::testing;

const char* kRealMeshes[] = {
    "bun_zipper.ply",
    "bunny.off",
    "bunny.stl",
    "armadillo.obj",
    "fandisk.off",
    "crank.off",
    "casting.off",
    "mask.off",
    "hemisphere.off",
    "skull.obj",
    "maneki-neko.off",
    "dragon_res2.ply",
    "dragon_res3.ply",
    "sphere.obj",
    "sphere_low.off",
    "chamfer-cube.off",
    "cube_att.obj",
    "cube_quads.obj",
    "octagon.obj",
    "suzanne.obj",
    "multiple_isolated_triangles.obj",
    "multiple_tetrahedrons.obj",
    "test_nm.obj",
    "extra_vertex.obj",
    "eof_test.obj",
    "deg_faces.obj",
    "non_manifold_wrap.obj",
};

class RealMesh : public ::testing::TestWithParam<const char*> {};

TEST_P(RealMesh, ExactRoundTrip) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  auto imported = import_mesh(test_mesh(GetParam()));
  ASSERT_TRUE(imported) << imported.error().message;
  const Mesh& mesh = imported->mesh;
  auto bytes = encode_hcs(mesh);
  ASSERT_TRUE(bytes) << bytes.error().message;
  auto decoded = decode_hcs(*bytes);
  ASSERT_TRUE(decoded) << decoded.error().message;
  auto reference = quantized_reference(mesh, 12);
  ASSERT_TRUE(reference);
  ASSERT_EQ(decoded->vertex_count(), reference->vertex_count());
  ASSERT_EQ(decoded->face_count(), reference->face_count());
  EXPECT_EQ(sorted_positions(*decoded), sorted_positions(*reference));
  EXPECT_EQ(canonical_faces(*decoded), canonical_faces(*reference));
  // Nothing is lost: same number of components and boundary edges.
  auto adj_in = Adjacency::build(*reference);
  auto adj_out = Adjacency::build(*decoded);
  ASSERT_TRUE(adj_in && adj_out);
  EXPECT_EQ(adj_out->boundary_edge_count(), adj_in->boundary_edge_count());
  EXPECT_EQ(adj_out->edge_count(), adj_in->edge_count());
}

INSTANTIATE_TEST_SUITE_P(Shared, RealMesh, ::testing::ValuesIn(kRealMeshes), [](const auto& info) {
  std::string name = info.param;
  for (char& c : name)
    if (!isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
});

// Every record boundary of a few real streams: a valid manifold mesh with
// the index's counts, no combinatorially degenerate face, and the same Euler
// characteristic and boundary edge count as the final mesh (topology kept).
class RealMeshPrefixes : public ::testing::TestWithParam<const char*> {};

TEST_P(RealMeshPrefixes, EveryRecordBoundaryIsValid) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  auto imported = import_mesh(test_mesh(GetParam()));
  ASSERT_TRUE(imported) << imported.error().message;
  auto bytes = encode_hcs(imported->mesh);
  ASSERT_TRUE(bytes) << bytes.error().message;
  auto index = read_stream_index(*bytes);
  ASSERT_TRUE(index);
  auto full = Adjacency::build(imported->mesh);
  ASSERT_TRUE(full);
  const int64_t euler_full =
      int64_t(imported->mesh.vertex_count()) - full->edge_count() + imported->mesh.face_count();
  IncrementalDecoder dec;
  uint64_t fed = 0;
  for (size_t i = 0; i < index->records.size(); ++i) {
    const uint64_t end = index->records[i].offset + index->records[i].size;
    auto r = dec.feed(std::span<const uint8_t>(bytes->data() + fed, end - fed));
    fed = end;
    ASSERT_TRUE(r) << r.error().message;
    const Mesh& m = dec.mesh();
    ASSERT_EQ(m.vertex_count(), index->records[i].vertices);
    ASSERT_EQ(m.face_count(), index->records[i].faces);
    ASSERT_TRUE(validate_arrays(m)) << "record " << i;
    auto adj = Adjacency::build(m);
    ASSERT_TRUE(adj) << "record " << i << ": " << adj.error().message;
    const int64_t euler = int64_t(m.vertex_count()) - adj->edge_count() + m.face_count();
    EXPECT_EQ(euler, euler_full) << "record " << i;
  }
  EXPECT_TRUE(dec.finished());
}

INSTANTIATE_TEST_SUITE_P(Shared, RealMeshPrefixes,
                         ::testing::Values("fandisk.off", "mask.off", "casting.off",
                                           "dragon_res3.ply", "suzanne.obj"),
                         [](const auto& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (!isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

}  // namespace
}  // namespace meshstream
