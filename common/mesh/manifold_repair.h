// Non-manifold detection and repair, after welding and dropping degenerate
// and duplicate faces (clean_mesh's order).
#pragma once

#include <cstdint>

#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream {

struct RepairCounts {
  uint32_t split_vertices = 0;  // vertex copies added (fan splits and detached faces)
  uint32_t detached_faces = 0;  // faces cut loose from an edge with more than two faces
  uint32_t flipped_faces = 0;   // faces re-oriented
};

// Refuses anything Adjacency::build would refuse, with kNonManifold and a
// message naming the first offence: an edge with more than two faces, an
// edge used twice in the same direction, or a vertex joining several fans
// (with its position, so a person can find it). Precondition: indices in
// range, no degenerate face. O(V + F).
Status check_manifold(const Mesh& mesh);

// Makes the mesh manifold and consistently oriented, in the spirit of
// Guéziec, Taubin, Lazarus, Horn, "Cutting and stitching: converting sets of
// polygons to manifold surfaces" (IEEE TVCG 2001), keeping every face:
//  1. orient each surface by breadth-first search across edges with exactly
//     two faces, flipping the minority of faces in each component;
//  2. split every vertex into one copy per fan of faces (fans connected
//     through two-face edges only), which also cuts edges with more than two
//     faces apart wherever their faces belong to different fans;
//  3. where an edge still has more than two faces, keep one consistently
//     oriented pair and detach the other faces (own vertex copies);
//  repeat until nothing changes. Copies keep the position and attributes.
// Fails with kNonManifold when a component cannot be oriented (Möbius-like).
// The result always passes Adjacency::build. O((V + F) * rounds), rounds
// is small (2-3 on real data).
Result<RepairCounts> make_manifold(Mesh& mesh);

}  // namespace meshstream
