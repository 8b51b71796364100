// Corner-table adjacency for manifold, consistently oriented triangle meshes
// (Rossignac's corner table, as in Draco and the Edgebreaker papers).
//
// Corner c = 3 * face + i is the i-th corner of a face and sits at vertex
// `vertex(c)`. `opposite(c)` is the corner across the edge facing c (the edge
// from vertex(next(c)) to vertex(prev(c))), or kNone on a boundary. All
// neighbour queries are O(1); a one-ring is O(valence).
//
// Build cost is O(V + F) time and about 40 bytes per face; it is rebuilt at
// every subdivision level and every decoded record, so it avoids hashing.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream {

inline constexpr uint32_t kNone = 0xFFFFFFFFu;

class Adjacency {
 public:
  // Builds the table. Fails with kNonManifold, naming the first offending
  // edge or vertex, when an edge has more than two faces, two faces use an
  // edge in the same direction (inconsistent orientation), or a vertex's faces
  // form more than one fan. Fails with kInvalidMesh on out-of-range indices or
  // degenerate triangles. Isolated vertices are allowed (valence 0).
  static Result<Adjacency> build(const Mesh& mesh);

  uint32_t vertex_count() const { return static_cast<uint32_t>(vertex_corner_.size()); }
  uint32_t face_count() const { return static_cast<uint32_t>(corner_vertex_.size() / 3); }
  uint32_t corner_count() const { return static_cast<uint32_t>(corner_vertex_.size()); }

  static uint32_t face(uint32_t corner) { return corner / 3; }
  static uint32_t next(uint32_t corner) { return corner % 3 == 2 ? corner - 2 : corner + 1; }
  static uint32_t prev(uint32_t corner) { return corner % 3 == 0 ? corner + 2 : corner - 1; }
  uint32_t vertex(uint32_t corner) const { return corner_vertex_[corner]; }
  uint32_t opposite(uint32_t corner) const { return opposite_[corner]; }

  // A corner at vertex v, or kNone for an isolated vertex. For a boundary
  // vertex it is the corner whose face comes first in counter-clockwise order
  // (the face whose edge (v, vertex(prev(c))) ... is on the boundary), so a
  // counter-clockwise swing from it visits every face of v.
  uint32_t vertex_corner(uint32_t v) const { return vertex_corner_[v]; }

  // Next corner at the same vertex, counter-clockwise (around the face normal),
  // or kNone when that crosses a boundary edge.
  uint32_t swing_ccw(uint32_t corner) const {
    uint32_t o = opposite_[next(corner)];
    return o == kNone ? kNone : next(o);
  }
  // Next corner at the same vertex, clockwise, or kNone at a boundary edge.
  uint32_t swing_cw(uint32_t corner) const {
    uint32_t o = opposite_[prev(corner)];
    return o == kNone ? kNone : prev(o);
  }

  bool is_boundary_vertex(uint32_t v) const { return is_boundary_[v] != 0; }
  bool is_isolated_vertex(uint32_t v) const { return vertex_corner_[v] == kNone; }
  // Number of neighbouring vertices (for a boundary vertex: faces + 1).
  uint32_t valence(uint32_t v) const;

  // The neighbours of v in counter-clockwise order. For an interior vertex the
  // cycle starts anywhere; for a boundary vertex it runs from one boundary
  // neighbour to the other. Clears `out` first; no allocation once `out` has
  // capacity.
  void one_ring(uint32_t v, std::vector<uint32_t>& out) const;
  // The corners at v in the same order as one_ring's faces.
  void vertex_corners(uint32_t v, std::vector<uint32_t>& out) const;

  // The face across each edge of f, kNone on a boundary: entry i is across
  // the edge opposite corner i (from vertex(3f+i+1) to vertex(3f+i+2)).
  std::array<uint32_t, 3> face_neighbors(uint32_t f) const {
    std::array<uint32_t, 3> n{};
    for (uint32_t i = 0; i < 3; ++i) {
      uint32_t o = opposite_[3 * f + i];
      n[i] = o == kNone ? kNone : face(o);
    }
    return n;
  }

  // Edges are named by a corner facing them; each undirected edge has one
  // canonical corner: the smaller of c and opposite(c). Enumerate with
  // `for c in corners: if is_edge_representative(c)`.
  bool is_edge_representative(uint32_t c) const {
    uint32_t o = opposite_[c];
    return o == kNone || c < o;
  }
  uint32_t edge_count() const { return edge_count_; }
  uint32_t boundary_edge_count() const { return boundary_edge_count_; }

 private:
  // The phases of build(), in order (see adjacency.cpp).
  Status copy_corners(const Mesh& mesh);
  Status link_opposites(uint32_t vertex_count);
  Status find_vertex_fans(uint32_t vertex_count);
  void count_edges();

  std::vector<uint32_t> corner_vertex_;
  std::vector<uint32_t> opposite_;
  std::vector<uint32_t> vertex_corner_;
  std::vector<uint8_t> is_boundary_;
  uint32_t edge_count_ = 0;
  uint32_t boundary_edge_count_ = 0;
};

}  // namespace meshstream
