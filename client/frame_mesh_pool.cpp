#include "client/frame_mesh_pool.h"

#include <algorithm>
#include <atomic>

#include "client/surface_attributes.h"

namespace meshstream::client {

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
  behind.attributes = behind.attributes || changes.attributes;
  behind.textures = behind.textures || changes.textures;
  if (behind.vertices.size() + behind.faces.size() + behind.moved.size() >
      mirror.positions.size() + mirror.triangles.size()) {
    behind.clear();
    behind.full = true;
  }
}

// Capacity for `needed` elements: at least `expected` when it has to grow.
template <class T>
void reserve_for(std::vector<T>& v, size_t needed, size_t expected) {
  if (v.capacity() < needed) v.reserve(std::max(needed, expected));
}

// Brings `mesh` to equal `mirror`, given what changed since it did.
void catch_up(Mesh& mesh, const MeshChanges& behind, const Mesh& mirror, uint32_t expected_vertices,
              uint32_t expected_faces) {
  reserve_for(mesh.positions, mirror.positions.size(), expected_vertices);
  reserve_for(mesh.triangles, mirror.triangles.size(), expected_faces);
  if (behind.full) {
    mesh.positions.assign(mirror.positions.begin(), mirror.positions.end());
    mesh.triangles.assign(mirror.triangles.begin(), mirror.triangles.end());
    copy_surface_attributes(mirror, mesh, true);
    return;
  }
  if (behind.attributes) copy_surface_attributes(mirror, mesh, behind.textures);
  // The mirror only grows between full changes: added vertices and faces are
  // in the lists, so resizing and copying the listed entries is exact.
  mesh.positions.resize(mirror.positions.size());
  mesh.triangles.resize(mirror.triangles.size());
  for (uint32_t v : behind.vertices) mesh.positions[v] = mirror.positions[v];
  for (uint32_t v : behind.moved) mesh.positions[v] = mirror.positions[v];
  for (uint32_t f : behind.faces) mesh.triangles[f] = mirror.triangles[f];
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
    catch_up(*k.mesh, k.behind, mirror, expected_vertices_, expected_faces_);
    if (k.behind.full) {
      ++stats_.whole_copies;
    } else {
      ++stats_.updates;
    }
    k.behind.clear();
    return k.mesh;
  }
  if (kept_.size() >= kMaxMeshes) kept_.erase(kept_.begin());  // its holders keep it alive
  auto mesh = std::make_shared<Mesh>();
  MeshChanges whole;
  whole.full = true;
  catch_up(*mesh, whole, mirror, expected_vertices_, expected_faces_);
  kept_.push_back(Kept{std::move(mesh), {}});
  ++stats_.whole_copies;
  return kept_.back().mesh;
}

}  // namespace meshstream::client
