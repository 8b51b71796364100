// Undirected edges of a triangle soup with every face that uses them, for
// meshes that may be non-manifold (where a corner table cannot be built).
// Shared by the statistics (topology.cpp) and the manifold repair (clean.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "common/mesh/mesh.h"

namespace meshstream {

// One use of an undirected edge by a face: the face's side from corner
// `local` to corner (local + 1) % 3.
struct EdgeUse {
  uint32_t face;
  uint8_t local;  // 0..2
  bool forward;   // the face walks the edge from `lo` to `hi`
};

// All edges, grouped: edge k is (lo[k], hi[k]) with lo < hi and its uses are
// uses[begin[k] .. begin[k + 1]). Edges are ordered by (lo, hi).
struct EdgeGroups {
  std::vector<uint32_t> lo, hi;
  std::vector<uint32_t> begin;  // size edge_count() + 1
  std::vector<EdgeUse> uses;

  uint32_t edge_count() const { return static_cast<uint32_t>(lo.size()); }
  uint32_t use_count(uint32_t e) const { return begin[e + 1] - begin[e]; }
};

// Groups the sides of every face by undirected edge. Faces with an index out
// of range or a repeated index are skipped (callers validate first).
// O(V + F) plus a sort per vertex of its outgoing edges (small). Allocates
// about 42 bytes per face for the result and, while building, 8 per vertex
// and 12 per face (the larger vertex of every side).
EdgeGroups build_edge_groups(const Mesh& mesh);

}  // namespace meshstream
