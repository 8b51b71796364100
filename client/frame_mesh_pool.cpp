#include "client/frame_mesh_pool.h"

#include <atomic>

namespace meshstream::client {

void copy_attributes(const Mesh& from, Mesh& to) {
  to.normals = from.normals;
  to.colors = from.colors;
  to.texcoords = from.texcoords;
  to.corner_normals = from.corner_normals;
  to.corner_colors = from.corner_colors;
  to.corner_texcoords = from.corner_texcoords;
  to.materials = from.materials;
  to.face_materials = from.face_materials;
  to.textures = from.textures;
  to.extra_attributes = from.extra_attributes;
}

namespace {

// Adds `changes` to what a kept mesh lacks; past one entry per vertex and
// face of the mirror, a whole copy is cheaper than the lists (and bounds
// them).
void fall_behind(MeshChanges& behind, const MeshChanges& changes, const Mesh& mirror) {
  if (behind.full) return;
  if (changes.full) {
    behind.clear();
    behind.full = true;
    return;
  }
  behind.vertices.insert(behind.vertices.end(), changes.vertices.begin(), changes.vertices.end());
  behind.faces.insert(behind.faces.end(), changes.faces.begin(), changes.faces.end());
  behind.moved.insert(behind.moved.end(), changes.moved.begin(), changes.moved.end());
  if (behind.vertices.size() + behind.faces.size() + behind.moved.size() >
      mirror.positions.size() + mirror.triangles.size()) {
    behind.clear();
    behind.full = true;
  }
}

// Brings `mesh` to equal `mirror`, given what changed since it did.
void catch_up(Mesh& mesh, const MeshChanges& behind, const Mesh& mirror) {
  if (behind.full) {
    mesh.positions.assign(mirror.positions.begin(), mirror.positions.end());
    mesh.triangles.assign(mirror.triangles.begin(), mirror.triangles.end());
    copy_attributes(mirror, mesh);
    return;
  }
  // The mirror only grows between full changes: added vertices and faces are
  // in the lists, so resizing and copying the listed entries is exact.
  mesh.positions.resize(mirror.positions.size());
  mesh.triangles.resize(mirror.triangles.size());
  for (uint32_t v : behind.vertices) mesh.positions[v] = mirror.positions[v];
  for (uint32_t v : behind.moved) mesh.positions[v] = mirror.positions[v];
  for (uint32_t f : behind.faces) mesh.triangles[f] = mirror.triangles[f];
  copy_attributes(mirror, mesh);
}

}  // namespace

std::shared_ptr<const Mesh> FrameMeshPool::share(const Mesh& mirror, const MeshChanges& changes) {
  for (Kept& k : kept_) fall_behind(k.behind, changes, mirror);
  for (Kept& k : kept_) {
    // Sole owner: no frame holds it any more, and none can get it again
    // except from us. The holders released it with a release decrement;
    // the fence orders our writes after their last reads.
    if (k.mesh.use_count() != 1) continue;
    std::atomic_thread_fence(std::memory_order_acquire);
    catch_up(*k.mesh, k.behind, mirror);
    if (k.behind.full) {
      ++stats_.whole_copies;
    } else {
      ++stats_.updates;
    }
    k.behind.clear();
    return k.mesh;
  }
  if (kept_.size() >= kMaxMeshes) kept_.erase(kept_.begin());  // its holders keep it alive
  kept_.push_back(Kept{std::make_shared<Mesh>(mirror), {}});
  ++stats_.whole_copies;
  return kept_.back().mesh;
}

}  // namespace meshstream::client
