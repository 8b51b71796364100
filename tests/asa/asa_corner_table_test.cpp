// The fast corner-table builder agrees with Adjacency::build, accepts and
// refuses the same meshes.
#include "tests/asa/asa_test_support.h"

#include "common/asa/corner_table.h"

namespace meshstream {
namespace {

void expect_same_as_adjacency(const Mesh& m, const char* what) {
  asa::CornerTableScratch scratch;
  std::vector<uint32_t> opposite;
  auto adj = Adjacency::build(m);
  auto ours = asa::build_opposites(m, opposite, scratch);
  ASSERT_EQ(adj.has_value(), ours.has_value()) << what;
  if (!adj) {
    EXPECT_EQ(adj.error().code, ours.error().code) << what << ": " << ours.error().message;
    return;
  }
  for (uint32_t c = 0; c < opposite.size(); ++c) ASSERT_EQ(opposite[c], adj->opposite(c)) << what << " corner " << c;
}

TEST(AsaCornerTable, MatchesAdjacencyOnProceduralMeshes) {
  expect_same_as_adjacency(asa_test::icosahedron(), "icosahedron");
  expect_same_as_adjacency(asa_test::flat_grid(7), "grid");
  Mesh m = asa_test::octahedron();
  m.triangles.push_back({0, 2, 4});
  expect_same_as_adjacency(m, "duplicate face");
  m = asa_test::octahedron();
  std::swap(m.triangles[0][1], m.triangles[0][2]);
  expect_same_as_adjacency(m, "flipped face");
  // Two fans joined at one vertex (a bow tie).
  Mesh bow;
  bow.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}};
  bow.triangles = {{0, 1, 2}, {0, 3, 4}};
  expect_same_as_adjacency(bow, "bow tie");
  // An edge with three faces.
  Mesh fin;
  fin.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  fin.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  expect_same_as_adjacency(fin, "three faces on an edge");
}

TEST(AsaCornerTable, MatchesAdjacencyOnRealMeshes) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  for (const char* name : {"bunny.off", "mask.off", "casting.off", "skull.obj"}) {
    expect_same_as_adjacency(asa_test::load(name), name);
  }
}

}  // namespace
}  // namespace meshstream
