// The fast corner-table builder agrees with Adjacency::build, accepts and
// refuses the same meshes.
#include <cmath>
#include <string>

#include "common/asa/corner_table.h"
#include "tests/asa/asa_test_support.h"

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
  for (uint32_t c = 0; c < opposite.size(); ++c)
    ASSERT_EQ(opposite[c], adj->opposite(c)) << what << " corner " << c;
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

// A closed bipyramid: two apices of valence n, a ring of valence-4 vertices.
Mesh bipyramid(uint32_t n) {
  Mesh m;
  for (uint32_t i = 0; i < n; ++i) {
    const float a = 6.2831853f * static_cast<float>(i) / static_cast<float>(n);
    m.positions.push_back({std::cos(a), std::sin(a), 0});
  }
  m.positions.push_back({0, 0, 1});
  m.positions.push_back({0, 0, -1});
  for (uint32_t i = 0; i < n; ++i) {
    m.triangles.push_back({i, (i + 1) % n, n});
    m.triangles.push_back({(i + 1) % n, i, n + 1});
  }
  return m;
}

TEST(AsaCornerTable, MatchesAdjacencyOnLargeFans) {
  // Fans matched with bit masks (up to 64 corners, several 4-wide groups)
  // and by sorting (more than 64).
  for (uint32_t n : {3u, 5u, 7u, 9u, 17u, 63u, 64u, 65u, 200u}) {
    Mesh m = bipyramid(n);
    expect_same_as_adjacency(m, ("bipyramid " + std::to_string(n)).c_str());
    // Open fan: drop one face at the top apex.
    Mesh open = m;
    open.triangles.erase(open.triangles.begin());
    expect_same_as_adjacency(open, ("open bipyramid " + std::to_string(n)).c_str());
    // Two fans at the top apex: drop two faces far apart (non-manifold vertex).
    if (n >= 5) {
      Mesh bow = m;
      bow.triangles.erase(bow.triangles.begin() + 2 * (n / 2));
      bow.triangles.erase(bow.triangles.begin());
      expect_same_as_adjacency(bow, ("two fans " + std::to_string(n)).c_str());
    }
    // A duplicated face: an edge used twice in the same direction.
    Mesh dup = m;
    dup.triangles.push_back(m.triangles[2]);
    expect_same_as_adjacency(dup, ("duplicate face " + std::to_string(n)).c_str());
  }
}

TEST(AsaCornerTable, AcrossIsTheOppositeCornersVertex) {
  for (const Mesh& m : {bipyramid(80), asa_test::flat_grid(5), asa_test::icosahedron()}) {
    asa::CornerTableScratch scratch;
    std::vector<uint32_t> opposite, across;
    ASSERT_TRUE(asa::build_opposites(m, opposite, across, scratch).has_value());
    ASSERT_EQ(across.size(), opposite.size());
    for (uint32_t c = 0; c < opposite.size(); ++c)
      ASSERT_EQ(across[c],
                opposite[c] == kNone ? kNone : m.triangles[opposite[c] / 3][opposite[c] % 3])
          << c;
  }
}

TEST(AsaCornerTable, MatchesAdjacencyOnRealMeshes) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  for (const char* name : {"bunny.off", "mask.off", "casting.off", "skull.obj"}) {
    expect_same_as_adjacency(asa_test::load(name), name);
  }
}

}  // namespace
}  // namespace meshstream
