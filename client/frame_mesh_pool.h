// The decoded meshes the display pipeline hands to its frames. A frame's
// mesh is shared and immutable while anyone holds it (the mailbox, the
// viewer, an observer), so each display update used to copy the whole
// pipeline mirror into a new mesh: O(mesh) per update, whatever the update
// changed. The pool keeps a few meshes and gives out one that no frame holds
// any more, bringing it up to date with only what changed in the mirror since
// it was last given out; a whole copy happens only when every mesh is still
// held (or so much changed that a copy is cheaper than the lists).
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "client/decoded_stream.h"
#include "common/mesh/mesh.h"

namespace meshstream::client {

class FrameMeshPool {
 public:
  // How the meshes given out were made, for tests and measurements.
  struct Stats {
    size_t whole_copies = 0;  // a new mesh, or a reused one copied whole
    size_t updates = 0;       // a reused mesh given only the changes
  };

  // A mesh equal to `mirror`, which `changes` changed since the previous
  // call (the first call, and any with changes.full, copy it whole). Nobody
  // else holds the returned mesh's storage for writing: the pool changes a
  // mesh only while it is the sole owner. O(changes) when a mesh is free.
  std::shared_ptr<const Mesh> share(const Mesh& mirror, const MeshChanges& changes);

  // The sizes the mirror is expected to grow to (the stream's final vertex
  // and face counts, bounded by what the bytes received can describe): a
  // mesh that must grow reserves that much at once instead of doubling, so
  // its arrays are not copied again and again as records arrive. Only a
  // capacity: the meshes still equal the mirror.
  void expect(uint32_t vertices, uint32_t faces) {
    expected_vertices_ = vertices;
    expected_faces_ = faces;
  }

  const Stats& stats() const { return stats_; }

  // At most this many meshes are kept; with all of them held elsewhere the
  // pool lets go of one (its holders keep it) and copies a new one.
  static constexpr size_t kMaxMeshes = 4;

 private:
  struct Kept {
    std::shared_ptr<Mesh> mesh;
    MeshChanges behind;  // what changed in the mirror since `mesh` equalled it
  };
  std::vector<Kept> kept_;
  Stats stats_;
  uint32_t expected_vertices_ = 0, expected_faces_ = 0;
};

}  // namespace meshstream::client
