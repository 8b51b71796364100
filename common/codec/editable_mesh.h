// A corner table that supports the two local edits of the progressive codec:
// removing an interior vertex and re-triangulating its hole as a fan
// (encoder, decimation), and the exact inverse, inserting a vertex into a fan
// patch (decoder, refinement). Corners, faces and vertices follow
// adjacency.h (corner c = 3 * face + i); positions are integer grid points.
//
// Why our own structure instead of rebuilding Adjacency per record: an edit
// touches O(valence) entries, so a record of m insertions costs O(m) instead
// of O(mesh). Encoder and decoder perform the same edits in the same order on
// this structure, so face slots, vertex corners and ring start corners are
// identical on both sides: the stream may name patches by positions in a ring
// without any canonical sorting.
//
// Face slots: an insertion rewrites the k-2 fan faces in place (star face S_j
// goes to the slot of fan face T_j) and appends S_0 and S_{k-1}; a removal
// reuses k-2 star slots and marks two slots dead (only the encoder removes).
#pragma once

#include <cstdint>
#include <vector>

#include "common/base/result.h"
#include "common/codec/quantize.h"
#include "common/mesh/adjacency.h"
#include "common/mesh/mesh.h"

namespace meshstream {

// Largest ring an edit handles (the codec limits removals to far less).
inline constexpr uint32_t kMaxPatchValence = 64;

static_assert(sizeof(Triangle) == 3 * sizeof(uint32_t), "faces are packed index triples");

class EditableMesh {
 public:
  // Builds from a manifold, consistently oriented mesh (checked through
  // Adjacency::build: kNonManifold / kInvalidMesh otherwise). O(V + F).
  static Result<EditableMesh> build(std::vector<Vec3i> positions, std::vector<Triangle> faces);

  static uint32_t face_of(uint32_t c) { return c / 3; }
  static uint32_t next(uint32_t c) { return c % 3 == 2 ? c - 2 : c + 1; }
  static uint32_t prev(uint32_t c) { return c % 3 == 0 ? c + 2 : c - 1; }
  // Faces are packed triples, so corner c is simply the c-th index.
  uint32_t vertex(uint32_t c) const { return reinterpret_cast<const uint32_t*>(faces_.data())[c]; }
  uint32_t opposite(uint32_t c) const { return opposite_[c]; }
  uint32_t swing_ccw(uint32_t c) const {
    const uint32_t o = opposite_[next(c)];
    return o == kNone ? kNone : next(o);
  }

  uint32_t vertex_count() const { return static_cast<uint32_t>(positions_.size()); }
  uint32_t face_slot_count() const { return static_cast<uint32_t>(faces_.size()); }
  bool is_boundary(uint32_t v) const { return boundary_[v] != 0; }
  bool is_isolated(uint32_t v) const { return vertex_corner_[v] == kNone; }
  bool face_dead(uint32_t f) const { return !dead_.empty() && dead_[f] != 0; }
  const std::vector<Vec3i>& positions() const { return positions_; }
  const std::vector<Triangle>& faces() const { return faces_; }

  // The star of v: `ring` its neighbours counter-clockwise, `corners` the
  // corners at v of its faces, corners[i] in face (v, ring[i], ring[i+1]).
  // Interior: |ring| == |corners|; boundary: |ring| == |corners| + 1, from
  // one boundary neighbour to the other. The start is vertex_corner(v), the
  // same on encoder and decoder. O(valence).
  void star(uint32_t v, std::vector<uint32_t>& ring, std::vector<uint32_t>& corners) const;

  // Encoder: removes vertex v whose star is (ring, corners), 3 <= k =
  // |ring| <= kMaxPatchValence, and fills the hole with the fan from
  // ring[apex]: T_j = (R_a, R_a+j, R_a+j+1), j = 1..k-2. A boundary vertex's
  // hole is closed by the new boundary edge (ring[k-1], ring[0]). The caller
  // has checked that no new edge already exists. O(k).
  void remove_vertex(uint32_t v, const std::vector<uint32_t>& ring,
                     const std::vector<uint32_t>& corners, uint32_t apex);

  // Decoder: inserts a new vertex at `position` into the fan patch around
  // ring[0] whose k-2 faces have the corners `fan_corners` at ring[0]
  // (fan_corners[j-1] in face (R_0, R_j, R_j+1)). `open` = kNone for an
  // interior vertex (k new faces replace k-2); for a boundary vertex it is
  // the index i of the boundary ring edge (R_i, R_i+1) that the vertex
  // re-enters (k-1 faces replace k-2). Returns the new vertex id; appends
  // every face slot it wrote to `touched`. The caller has validated the
  // patch (refinement_codec's resolve_patch). O(k).
  uint32_t insert_vertex(const std::vector<uint32_t>& ring,
                         const std::vector<uint32_t>& fan_corners, uint32_t open, Vec3i position,
                         std::vector<uint32_t>* touched);

  // Cache hints for the decoder, which visits vertices in an order the
  // memory layout does not follow: asks for v's start corner and position
  // (what star(v), the patch scores and insert_vertex read about v) ahead
  // of use, so the misses overlap other work. No effect on results.
  void prefetch_vertex(uint32_t v) const {
    if (v < positions_.size()) {
      __builtin_prefetch(&vertex_corner_[v]);
      __builtin_prefetch(&positions_[v]);
    }
  }

  // The same for the first face of v's star (its corner's vertex and
  // opposite entries): worth it once vertex_corner(v) is in cache.
  void prefetch_first_face(uint32_t v) const {
    if (v >= vertex_corner_.size()) return;
    const uint32_t c = vertex_corner_[v];
    if (c >= opposite_.size()) return;
    __builtin_prefetch(&opposite_[c]);
    __builtin_prefetch(&faces_[c / 3]);
  }

  // The same for the face of corner c (its vertex and opposite entries).
  void prefetch_corner(uint32_t c) const {
    if (c < opposite_.size()) {
      __builtin_prefetch(&opposite_[c]);
      __builtin_prefetch(&faces_[c / 3]);
    }
  }

  // Moves vertex v (successive approximation: a plane record sharpened it).
  void set_position(uint32_t v, Vec3i p) { positions_[v] = p; }

  // Reserves room for a mesh of this size (avoids regrowth while decoding).
  void reserve(uint32_t vertices, uint32_t faces) {
    positions_.reserve(vertices);
    vertex_corner_.reserve(vertices);
    boundary_.reserve(vertices);
    faces_.reserve(faces);
    opposite_.reserve(3 * size_t(faces));
  }

  // The live faces as a plain triangle list (dead slots skipped) and the
  // positions; vertices keep their ids.
  std::vector<Triangle> live_faces() const;
  // Moves the face slots out (the decoder's output, which has no dead
  // slots); the mesh is left without faces and must be discarded.
  std::vector<Triangle> release_faces() { return std::move(faces_); }

 private:
  void set_opposite(uint32_t c, uint32_t value) { opposite_[c] = value; }
  void set_vertex_corner(uint32_t v, uint32_t value) { vertex_corner_[v] = value; }
  void set_face(uint32_t f, const Triangle& t) { faces_[f] = t; }

  std::vector<Vec3i> positions_;
  std::vector<Triangle> faces_;
  std::vector<uint32_t> opposite_;
  std::vector<uint32_t> vertex_corner_;
  std::vector<uint8_t> boundary_;
  std::vector<uint8_t> dead_;
};

}  // namespace meshstream
