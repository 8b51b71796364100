// One subdivision level: new edge points by the Butterfly rules and the
// triangles that replace each face, with the corner table of the result
// derived directly (no re-hashing of edges), so levels chain in O(output).
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

#include "common/asa/butterfly_stencils.h"
#include "common/asa/closure.h"
#include "common/asa/edge_points.h"
#include "common/asa/level_mesh.h"
#include "common/asa/subdivide.h"

namespace meshstream::asa {

struct SplitInput {
  LevelView mesh;
  const Vec4f* colors = nullptr;     // per vertex, or null
  const Vec2f* texcoords = nullptr;  // per vertex, or null
  const ButterflyWeights* weights = nullptr;
  EdgePlacement placement = EdgePlacement::kZorin;
  bool want_topology = true;         // fill opposite/feature/valence data for another level
  const uint32_t* source = nullptr;  // per face: input face it descends from; null = untracked
  // Adaptive split with want_topology: the level's unit face normals; the
  // output then gets its own (out.normals, out.fresh). Null: none written.
  const Vec3f* normals = nullptr;
  // Per vertex id: the two vertices a new vertex was made between, at
  // 2 id and 2 id + 1 (for corner attributes, corner_attributes.h); sized
  // by the caller for every new vertex; null: not recorded.
  uint32_t* parents = nullptr;
};

struct SplitScratch {
  std::vector<uint32_t> edge_vertex;  // per corner: new vertex on the faced edge or kNone
  std::vector<uint32_t> slot_a, slot_b;
  std::vector<uint32_t> kept_base;  // per face: first output corner of a kept face, else kNone
  std::vector<uint32_t> naming;     // adaptive: the corner naming each split edge, in id order
  std::vector<uint32_t> touched;    // adaptive: old vertices whose faces changed (repeats allowed)
  uint32_t fresh_count = 0;         // adaptive: output faces that are not copies of a parent face
  EdgePointScratch points;
};

// Sizes out's colours and texture coordinates for V old + E new vertices
// (copying the old ones), or clears those the input does not have.
inline void start_vertex_attributes(const SplitInput& in, uint32_t V, uint32_t E, LevelMesh& out) {
  if (in.colors) {
    out.colors.resize(static_cast<size_t>(V) + E);
    std::memcpy(out.colors.data(), in.colors, sizeof(Vec4f) * V);
  } else {
    out.colors.clear();
  }
  if (in.texcoords) {
    out.texcoords.resize(static_cast<size_t>(V) + E);
    std::memcpy(out.texcoords.data(), in.texcoords, sizeof(Vec2f) * V);
  } else {
    out.texcoords.clear();
  }
}

// New vertex `id` on the edge a-b: the average of the endpoints' attributes
// (linear, so colours stay in range and texture coordinates on their chart).
inline void average_vertex_attributes(const SplitInput& in, uint32_t a, uint32_t b, uint32_t id,
                                      LevelMesh& out) {
  if (in.parents) {
    in.parents[2 * size_t(id)] = a;
    in.parents[2 * size_t(id) + 1] = b;
  }
  if (in.colors) {
    const Vec4f ca = in.colors[a], cb = in.colors[b];
    out.colors[id] = {(ca.x + cb.x) * 0.5f, (ca.y + cb.y) * 0.5f, (ca.z + cb.z) * 0.5f,
                      (ca.w + cb.w) * 0.5f};
  }
  if (in.texcoords) {
    const Vec2f ta = in.texcoords[a], tb = in.texcoords[b];
    out.texcoords[id] = {(ta.x + tb.x) * 0.5f, (ta.y + tb.y) * 0.5f};
  }
}

// Uniform 1-to-4 split of every face (classic modified Butterfly).
// out gets V + E vertices (old ones first, bit-identical) and 4F faces:
// face 4f + i is the corner child at vertex i of f, 4f + 3 the middle one.
// O(V + F) time; no allocation once the buffers have capacity.
void split_uniform(const SplitInput& in, SplitScratch& scratch, LevelMesh& out,
                   std::vector<FaceKind>* face_kind);

// Adaptive split following the closure's per-face actions and split edges.
// Output faces appear in input face order (each face's children together).
// With in.normals and want_topology, out.normals holds every output face's
// unit normal (bit-identical to compute_face_normals) and out.fresh marks the
// faces that are not unchanged copies of a parent face. With want_topology,
// out.valence (faces per vertex) and out.vertex_features are filled too.
void split_adaptive(const SplitInput& in, const ClosureBuffers& closure, SplitScratch& scratch,
                    LevelMesh& out, std::vector<FaceKind>* face_kind);

}  // namespace meshstream::asa
