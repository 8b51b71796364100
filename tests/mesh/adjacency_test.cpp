#include "common/mesh/adjacency.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace meshstream {
namespace {

Mesh octahedron() {
  Mesh m;
  m.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                 {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return m;
}

// Two triangles sharing edge (1,2): a square with four boundary edges.
Mesh square() {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  m.triangles = {{0, 1, 2}, {2, 1, 3}};
  return m;
}

TEST(Adjacency, ClosedOctahedronHasNoBoundaryAndValenceFour) {
  auto adj = Adjacency::build(octahedron());
  ASSERT_TRUE(adj) << adj.error().message;
  EXPECT_EQ(adj->edge_count(), 12u);
  EXPECT_EQ(adj->boundary_edge_count(), 0u);
  for (uint32_t v = 0; v < 6; ++v) {
    EXPECT_FALSE(adj->is_boundary_vertex(v));
    EXPECT_EQ(adj->valence(v), 4u);
  }
  for (uint32_t c = 0; c < adj->corner_count(); ++c) {
    uint32_t o = adj->opposite(c);
    ASSERT_NE(o, kNone);
    EXPECT_EQ(adj->opposite(o), c);
    // The shared edge is the same pair of vertices, traversed the other way.
    EXPECT_EQ(adj->vertex(Adjacency::next(c)), adj->vertex(Adjacency::prev(o)));
    EXPECT_EQ(adj->vertex(Adjacency::prev(c)), adj->vertex(Adjacency::next(o)));
  }
}

TEST(Adjacency, OneRingIsCounterClockwiseCycle) {
  Mesh m = octahedron();
  auto adj = Adjacency::build(m);
  ASSERT_TRUE(adj);
  std::vector<uint32_t> ring;
  adj->one_ring(4, ring);  // top vertex, seen from +z: 0, 2, 1, 3 counter-clockwise
  ASSERT_EQ(ring.size(), 4u);
  auto it = std::find(ring.begin(), ring.end(), 0u);
  ASSERT_NE(it, ring.end());
  std::rotate(ring.begin(), it, ring.end());
  EXPECT_EQ(ring, (std::vector<uint32_t>{0, 2, 1, 3}));
}

TEST(Adjacency, BoundaryRingRunsFromBoundaryToBoundary) {
  auto adj = Adjacency::build(square());
  ASSERT_TRUE(adj);
  EXPECT_EQ(adj->boundary_edge_count(), 4u);
  EXPECT_EQ(adj->edge_count(), 5u);
  std::vector<uint32_t> ring;
  adj->one_ring(1, ring);
  EXPECT_EQ(ring, (std::vector<uint32_t>{3, 2, 0}));
  EXPECT_EQ(adj->valence(1), 3u);
  EXPECT_TRUE(adj->is_boundary_vertex(1));
  auto n = adj->face_neighbors(0);
  EXPECT_EQ(n[0], 1u);  // across edge (1,2)
  EXPECT_EQ(n[1], kNone);
  EXPECT_EQ(n[2], kNone);
}

TEST(Adjacency, RefusesEdgeWithThreeFaces) {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  m.triangles = {{0, 1, 2}, {1, 0, 3}, {1, 0, 4}};
  auto adj = Adjacency::build(m);
  ASSERT_FALSE(adj);
  EXPECT_EQ(adj.error().code, ErrorCode::kNonManifold);
}

TEST(Adjacency, RefusesBowtieVertex) {
  Mesh m;  // two triangles touching only at vertex 0
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}};
  m.triangles = {{0, 1, 2}, {0, 3, 4}};
  auto adj = Adjacency::build(m);
  ASSERT_FALSE(adj);
  EXPECT_EQ(adj.error().code, ErrorCode::kNonManifold);
  EXPECT_NE(adj.error().message.find("vertex 0"), std::string::npos) << adj.error().message;
}

TEST(Adjacency, RefusesInconsistentOrientation) {
  Mesh m = square();
  m.triangles[1] = {1, 2, 3};  // same direction on edge (1,2) as triangle 0
  auto adj = Adjacency::build(m);
  ASSERT_FALSE(adj);
  EXPECT_EQ(adj.error().code, ErrorCode::kNonManifold);
}

}  // namespace
}  // namespace meshstream
