// Checks shared by the mesh tests: corner-table invariants against the
// independent statistics of topology.h.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "common/mesh/adjacency.h"
#include "common/mesh/topology.h"

namespace meshstream::testing {

// Signed volume (positive when faces are counter-clockwise seen from outside).
inline double signed_volume(const Mesh& mesh) {
  double volume = 0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3d a = to_double(mesh.positions[t[0]]), b = to_double(mesh.positions[t[1]]),
                c = to_double(mesh.positions[t[2]]);
    volume += dot(a, cross(b, c)) / 6.0;
  }
  return volume;
}

// Builds the corner table and checks, for every corner, edge and vertex:
// opposite() is an involution across the same edge reversed; edges with two
// faces are exactly the non-boundary ones; interior one-rings are closed
// cycles of distinct vertices whose consecutive pairs are faces with v, in
// counter-clockwise order; boundary one-rings run between two boundary
// edges; face_neighbors agree with opposite(); counts and the Euler
// characteristic equal compute_stats's.
inline void expect_adjacency_invariants(const Mesh& mesh, const std::string& label) {
  auto built = Adjacency::build(mesh);
  ASSERT_TRUE(built) << label << ": " << built.error().message;
  const Adjacency& adj = *built;
  const MeshStats stats = compute_stats(mesh);

  uint32_t broken_opposites = 0;
  for (uint32_t c = 0; c < adj.corner_count(); ++c) {
    const uint32_t o = adj.opposite(c);
    if (o == kNone) continue;
    broken_opposites += adj.opposite(o) != c ||
                        adj.vertex(Adjacency::next(c)) != adj.vertex(Adjacency::prev(o)) ||
                        adj.vertex(Adjacency::prev(c)) != adj.vertex(Adjacency::next(o));
  }
  EXPECT_EQ(broken_opposites, 0u) << label;

  uint32_t edges = 0, boundary = 0;
  for (uint32_t c = 0; c < adj.corner_count(); ++c) {
    if (!adj.is_edge_representative(c)) continue;
    ++edges;
    boundary += adj.opposite(c) == kNone;
  }
  EXPECT_EQ(edges, stats.edges) << label;
  EXPECT_EQ(boundary, stats.boundary_edges) << label;
  EXPECT_EQ(adj.edge_count(), stats.edges) << label;
  EXPECT_EQ(adj.boundary_edge_count(), stats.boundary_edges) << label;
  const int64_t euler =
      static_cast<int64_t>(stats.referenced_vertices) - adj.edge_count() + adj.face_count();
  EXPECT_EQ(euler, stats.euler) << label;

  uint32_t bad_neighbors = 0;
  for (uint32_t f = 0; f < adj.face_count(); ++f) {
    const auto n = adj.face_neighbors(f);
    for (uint32_t i = 0; i < 3; ++i) {
      const uint32_t o = adj.opposite(3 * f + i);
      bad_neighbors += n[i] != (o == kNone ? kNone : Adjacency::face(o));
    }
  }
  EXPECT_EQ(bad_neighbors, 0u) << label;

  // Faces as sorted triples to look up (v, a, b) quickly.
  std::vector<Triangle> directed;
  directed.reserve(3 * mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) {
    directed.push_back(t);
    directed.push_back({t[1], t[2], t[0]});
    directed.push_back({t[2], t[0], t[1]});
  }
  std::sort(directed.begin(), directed.end());
  auto has_face = [&](uint32_t v, uint32_t a, uint32_t b) {
    return std::binary_search(directed.begin(), directed.end(), Triangle{v, a, b});
  };

  std::vector<uint32_t> ring, sorted;
  uint32_t bad_rings = 0, boundary_vertices = 0;
  for (uint32_t v = 0; v < adj.vertex_count(); ++v) {
    if (adj.is_isolated_vertex(v)) continue;
    adj.one_ring(v, ring);
    sorted = ring;
    std::sort(sorted.begin(), sorted.end());
    const bool distinct = std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end();
    bool ok = distinct && ring.size() == adj.valence(v) && ring.size() >= 2;
    if (adj.is_boundary_vertex(v)) {
      ++boundary_vertices;
      for (size_t i = 0; ok && i + 1 < ring.size(); ++i) ok = has_face(v, ring[i], ring[i + 1]);
      // The ring is not closed: no face (v, last, first).
      ok = ok && !has_face(v, ring.back(), ring.front());
    } else {
      ok = ok && ring.size() >= 3;
      for (size_t i = 0; ok && i < ring.size(); ++i)
        ok = has_face(v, ring[i], ring[(i + 1) % ring.size()]);
    }
    bad_rings += !ok;
  }
  EXPECT_EQ(bad_rings, 0u) << label;
  // In a manifold mesh every boundary vertex has exactly two boundary edges.
  EXPECT_EQ(boundary_vertices, stats.boundary_edges) << label;
}

}  // namespace meshstream::testing
