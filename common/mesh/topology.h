// Topological facts about a triangle mesh — also a non-manifold one, so
// `meshstream info` and the tests can describe a file as it is, before any
// repair. Uses edge grouping and union-find, never the corner table.
#pragma once

#include <cstdint>

#include "common/mesh/edge_groups.h"
#include "common/mesh/mesh.h"
#include "common/mesh/union_find.h"

namespace meshstream {

struct MeshStats {
  uint32_t vertices = 0;             // all vertices in the arrays
  uint32_t referenced_vertices = 0;  // used by at least one face
  uint32_t isolated_vertices = 0;    // vertices - referenced_vertices
  uint32_t faces = 0;
  uint32_t invalid_faces = 0;          // out-of-range or repeated index: ignored below
  uint32_t duplicate_faces = 0;        // same vertex set as an earlier face
  uint32_t edges = 0;                  // distinct undirected edges
  uint32_t boundary_edges = 0;         // edges with one face
  uint32_t boundary_loops = 0;         // connected groups of boundary edges
  uint32_t components = 0;             // face-connected parts (a shared vertex connects)
  uint32_t nonmanifold_edges = 0;      // edges with more than two faces
  uint32_t nonmanifold_vertices = 0;   // vertices whose faces form more than one fan
  uint32_t orientation_conflicts = 0;  // two-face edges walked twice in the same direction
  int64_t euler = 0;                   // referenced_vertices - edges + faces (valid faces)
  bool manifold = false;               // no non-manifold edge and no non-manifold vertex
  // (2 * components - euler - boundary_loops) / 2: meaningful only when manifold
  // and consistently oriented; genus_valid says so.
  int64_t genus = 0;
  bool genus_valid = false;
  BoundingBox bbox;
};

// Computes the statistics above, with the definitions of
// ../shared/meshes/MANIFEST.md: a vertex's faces form one fan when they are
// connected through edges incident to that vertex; components join faces
// that share a vertex. Any input is accepted; faces with an out-of-range or
// repeated index are counted in invalid_faces and otherwise ignored.
// O(V + F) time (plus small per-vertex sorts), O(V + F) memory.
MeshStats compute_stats(const Mesh& mesh);

// The part of the statistics that decides whether a mesh needs repair, from
// edge groups already built (build_edge_groups(mesh)): import needs only
// this, and hands the same groups on to the repair.
struct ManifoldCounts {
  uint32_t nonmanifold_edges = 0;
  uint32_t nonmanifold_vertices = 0;
  uint32_t orientation_conflicts = 0;
  bool manifold() const { return nonmanifold_edges == 0 && nonmanifold_vertices == 0; }
};
ManifoldCounts count_nonmanifold(const Mesh& mesh, const EdgeGroups& groups);

// The corners of every vertex joined into fans through the two-face edges
// alone (at both endpoints of each): what the manifold repair's first round
// starts from. 5 bytes a corner.
UnionFind two_face_fans(const Mesh& mesh, const EdgeGroups& groups);

// count_nonmanifold from those fans (built by two_face_fans from the same
// groups): the faces around an edge with more than two faces are joined in
// a small structure of their own, so import needs one union-find over the
// corners, not two, and hands `fans` on to the repair (finds compress its
// paths, the sets stay the same).
ManifoldCounts count_nonmanifold(const Mesh& mesh, const EdgeGroups& groups, UnionFind& fans);

}  // namespace meshstream
