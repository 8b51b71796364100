// Undirected edges of a triangle soup with every face that uses them, for
// meshes that may be non-manifold (where a corner table cannot be built).
// Shared by the statistics (topology.cpp) and the manifold repair (clean.cpp).
#pragma once

#include <cstdint>
#include <utility>
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

// How a face changed since its edge groups were built (update_edge_groups).
enum FaceChange : uint8_t {
  kFaceKept = 0,
  kFaceReversed = 1,    // reverse_face: the same vertices, walked the other way
  kFaceRenumbered = 2,  // some corner now holds another vertex (may be reversed too)
};

// Brings `groups`, built for a mesh with the same faces but for the changes
// in `change` (one entry per face, FaceChange bits), up to date with `mesh`:
// the arrays afterwards are exactly build_edge_groups(mesh)'s.
// `old_triangles` holds every renumbered face with its triangle from before
// (any order). The sides of renumbered faces are taken out and merged back in
// at their new edges, reversed ones are fixed in place; the edges between
// move in blocks (memmove). In place (no second copy of the groups), and
// about O(changed sides * log edges) besides the moves: for the repair, whose
// rounds change a few faces of millions. Precondition: all faces usable
// (indices in range, no repeated vertex); groups that do not match the
// promise are built afresh.
void update_edge_groups(EdgeGroups& groups, const Mesh& mesh, const std::vector<uint8_t>& change,
                        const std::vector<std::pair<uint32_t, Triangle>>& old_triangles);

}  // namespace meshstream
