// Non-manifold detection and repair, after welding and dropping degenerate
// and duplicate faces (clean_mesh's order).
#pragma once

#include <cstdint>

#include "common/base/result.h"
#include "common/mesh/edge_groups.h"
#include "common/mesh/mesh.h"
#include "common/mesh/union_find.h"

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
//  1. decide which faces stay joined across each edge: both faces of a
//     two-face edge; at an edge with more than two faces, a matching of
//     consistently oriented pairs, preferring faces already connected around
//     both endpoints, then faces whose normals agree (the surface continuing
//     most smoothly; fins and crossing sheets are cut off);
//  2. orient each surface by breadth-first search across the joins, flipping
//     the minority of faces; a pairing at a non-manifold edge that would
//     contradict the orientation is cut instead;
//  3. split every vertex into one copy per fan of joined faces;
//  4. where an edge still has more than two faces, keep the best pair and
//     detach the other faces (own vertex copies);
//  repeat until nothing changes. Copies keep the position and attributes.
// Fails with kNonManifold when a surface is non-orientable through its
// two-face edges alone (Möbius-like). The result always passes
// Adjacency::build (checked without building one: see make_manifold's last
// step). O((V + F) * rounds); rounds is small (2-3 on real data); the edge
// groups are updated in place between rounds, never rebuilt.
Result<RepairCounts> make_manifold(Mesh& mesh);
// The same, starting from build_edge_groups(mesh) already built by the
// caller (import builds them to decide whether to repair at all). With
// `final_groups`, the edge groups of the repaired mesh are handed back
// (import's flap check reads them instead of building them again).
Result<RepairCounts> make_manifold(Mesh& mesh, EdgeGroups groups,
                                   EdgeGroups* final_groups = nullptr);
// The same, with two_face_fans(mesh, groups) too already built by the caller
// (import counts the non-manifold vertices with them).
Result<RepairCounts> make_manifold(Mesh& mesh, EdgeGroups groups, UnionFind fans,
                                   EdgeGroups* final_groups);

}  // namespace meshstream
