// Incremental ASA for the streaming client: a refinement record changes a
// few faces of the decoded mesh, so only the display triangles of the faces
// near them are recomputed and the rest are reused.
//
// How: the display mesh is kept per decoded face (its children: 1 face kept,
// 2 bisected, 4 split, as common/asa emits them, each face's children
// together and in face order) plus one shared vertex per split decoded edge.
// An update takes the faces the records touched, widens them by
// `dirty_rings` vertex rings (everything whose flatness, closure or
// Butterfly stencil can see a changed face), cuts out that region plus
// `context_rings` more rings as a submesh, runs the ordinary subdivide() on
// it and replaces the children of the dirty faces with the submesh's. Both
// sides of every edge on the region's border must still agree on whether it
// is split and where its new vertex is, else the update reports failure and
// the caller recomputes everything. The result has the same triangles at the
// same positions as subdivide() on the whole mesh; vertex and face order may
// differ.
//
// Scope: one ASA level (options.levels == 1). With more levels a level's
// red-green state (which triangles are green) is not visible through the
// public subdivide() call, so the caller uses the full path.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "client/decoded_stream.h"
#include "common/asa/subdivide.h"
#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream::client {

class IncrementalAsa {
 public:
  // Whether options can be handled incrementally at all.
  static bool supports(const AsaOptions& options) { return options.levels == 1; }

  // Forgets the state; the next update must be a rebuild.
  void reset();
  bool ready() const { return ready_; }

  // Adopts `result` = subdivide(mesh, options) of the whole mesh as the
  // state to update from. O(output). False when the result is not in the
  // expected shape (the state stays unusable).
  bool adopt(const Mesh& mesh, const AsaOptions& options, const AsaResult& result);

  // Faces a region update would run subdivide() on (dirty region plus
  // context), or UINT32_MAX when the region exceeds `limit` faces. Updates
  // the vertex->face incidences to `mesh` first, so call it once per update,
  // before update(). O(region).
  uint32_t plan(const Mesh& mesh, const MeshChanges& changes, uint32_t limit);

  // Recomputes the planned region of `mesh`. False when the region could
  // not be merged consistently (the caller rebuilds; the state is reset).
  bool update(const Mesh& mesh, const AsaOptions& options, AsaWorkspace& workspace);

  // The display mesh and per-face kinds. O(output).
  void assemble(const Mesh& mesh, Mesh& out, std::vector<FaceKind>& kinds) const;

  uint32_t dirty_rings = 3;
  uint32_t context_rings = 3;
  uint32_t last_region_faces = 0;  // dirty faces of the last update
  uint32_t last_submesh_faces = 0;

 private:
  static constexpr uint32_t kMid = 0x80000000u;  // id = midpoint slot | kMid
  static uint64_t edge_key(uint32_t a, uint32_t b) {
    return a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a;
  }
  void sync_incidence(const Mesh& mesh, const MeshChanges& changes);
  void release_children(uint32_t face, std::vector<uint32_t>& touched_slots);
  uint32_t acquire_midpoint(uint32_t a, uint32_t b, const Vec3f& p, bool& conflict,
                            std::vector<uint32_t>& touched_slots);
  uint32_t faces_on_edge(uint32_t a, uint32_t b) const;

  bool ready_ = false;
  std::vector<Triangle> tris_;                      // decoded triangles the state reflects
  std::vector<std::vector<uint32_t>> star_;         // vertex -> incident faces
  std::vector<uint8_t> child_count_;                // per face: 1, 2 or 4
  std::vector<FaceKind> kind_;                      // per face
  std::vector<Triangle> children_;                  // 4 per face, encoded ids
  std::vector<Vec3f> mid_pos_;
  std::vector<uint32_t> mid_refs_;
  std::vector<uint64_t> mid_edge_;
  std::vector<uint32_t> free_slots_;
  std::unordered_map<uint64_t, uint32_t> mid_of_edge_;

  // Plan of the current update.
  std::vector<uint32_t> region_;    // dirty faces, then context faces
  uint32_t region_dirty_ = 0;       // how many of region_ are dirty
  std::vector<uint32_t> face_mark_; // epoch stamps
  uint32_t epoch_ = 0;
};

}  // namespace meshstream::client
