// Patches against the current mesh: which faces of a walk vertex's star are
// still free, where a fan of k - 2 faces fits and in which order the
// candidates rank, the patch's boundary edges, and the insertion of its
// vertex (the one step that grows the state). Shared by encoder and decoder.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/codec/editable_mesh.h"
#include "common/codec/embedded_geometry.h"
#include "common/codec/refinement_state.h"

namespace meshstream {

// One patch resolved against the current mesh.
struct ResolvedPatch {
  std::vector<uint32_t> ring;         // R_0 = apex, ..., R_k-1
  std::vector<uint32_t> fan_corners;  // k-2 corners at the apex
};

// Marks in `used` (one entry per face of u's star) the faces that hold a
// vertex inserted in the current layer: they belong to a patch already
// restored, so no fan can use them. Returns the number of free faces; a
// walk vertex with none cannot be an apex and codes nothing. O(faces).
uint32_t mark_taken_faces(const RefinementState& s, const std::vector<uint32_t>& star_ring,
                          uint32_t faces, std::vector<uint8_t>& used);

// The number of u's faces that hold no vertex inserted in the current layer,
// from counts apply_patch keeps (no swing around u needed). Equals what
// mark_taken_faces finds.
inline uint32_t free_face_count(const RefinementState& s, uint32_t u) {
  const RefinementState::VertexEntry& e = s.vertices[u];
  const uint32_t faces = e.valence - (s.mesh.is_boundary(u) ? 1 : 0);
  const uint32_t taken = e.taken_layer == s.layer ? e.taken : 0;
  return faces > taken ? faces - taken : 0;
}

// Resolves the patch whose first fan face is star index r and whose vertex
// has valence k, given the apex's star. False when it does not fit (r or k
// out of range for the star, a fan crossing the boundary or wrapping onto
// itself). O(k).
bool resolve_patch(const EditableMesh& mesh, uint32_t apex, const std::vector<uint32_t>& star_ring,
                   const std::vector<uint32_t>& star_corners, uint32_t r, uint32_t k,
                   ResolvedPatch& out);

// Indices i of the patch's ring edges (R_i, R_i+1) that are boundary edges
// of the current mesh: where a removed boundary vertex may re-enter.
void patch_boundary_edges(const EditableMesh& mesh, const ResolvedPatch& patch,
                          std::vector<uint32_t>& out);

// The first-face indices r (into the apex's star) where a fan of k-2 faces
// fits and overlaps no face marked in `used`, best candidate first: by the
// sum of the squared lengths of the fan's diagonals (k >= 4) or of the
// edge opposite the apex (k = 3), larger first, ties by r. Integer-exact.
// O(faces * k).
void rank_patch_starts(const EditableMesh& mesh, uint32_t apex,
                       const std::vector<uint32_t>& star_ring, const std::vector<uint8_t>& used,
                       uint32_t k, std::vector<uint32_t>& out);

// The decoder's shortcut: the same as rank_patch_starts(...)[rank], or
// kNone when there are not more than `rank` candidates. Rank 0 (the common
// case) is one pass over the candidates instead of a sort. `scratch_starts`
// is working space kept by the caller (no allocation per call).
uint32_t select_patch_start(const EditableMesh& mesh, uint32_t apex,
                            const std::vector<uint32_t>& star_ring,
                            const std::vector<uint8_t>& used, uint32_t k, uint32_t rank,
                            std::vector<uint32_t>& scratch_starts);

// rank_patch_starts with the candidates' scores in the same order.
void rank_patch_starts(const EditableMesh& mesh, uint32_t apex,
                       const std::vector<uint32_t>& star_ring, const std::vector<uint8_t>& used,
                       uint32_t k, std::vector<uint32_t>& out, std::vector<int64_t>& scores);
// Inserts a vertex into a resolved patch and links it after the apex in the
// order list. Returns its id; appends written face slots to `touched`.
uint32_t apply_patch(RefinementState& state, const ResolvedPatch& patch, uint32_t open,
                     Vec3i position, std::vector<uint32_t>* touched);
// The same for an embedded vertex: records its geometry and inserts it at
// reconstruct(geometry).
uint32_t apply_patch(RefinementState& state, const ResolvedPatch& patch, uint32_t open,
                     const VertexGeometry& geometry, std::vector<uint32_t>* touched);

// The scoring of patch starts itself, for the structure record reader's
// format-3 path (which needs the scores for the rank's context).
// Scratch of the start scoring: on the stack for ordinary stars, on the
// heap for huge ones. The decoder keeps one for a whole record (prepare per
// star) instead of building one per patch.
struct StartScratch {
  static constexpr uint32_t kSmall = 64;
  int64_t edge_small[2 * kSmall], score_small[kSmall];  // edge: wrapped copy after the end
  uint32_t start_small[kSmall];
  std::vector<int64_t> edge_big, score_big;
  std::vector<uint32_t> start_big;
  int64_t* edge = edge_small;
  int64_t* score = score_small;
  uint32_t* start = start_small;
  StartScratch() = default;
  explicit StartScratch(uint32_t faces) { prepare(faces); }
  StartScratch(const StartScratch&) = delete;
  StartScratch& operator=(const StartScratch&) = delete;
  void prepare(uint32_t faces) {
    if (faces > kSmall) {
      if (score_big.size() < faces) {
        edge_big.resize(2 * size_t(faces));
        score_big.resize(faces);
        start_big.resize(faces);
      }
      edge = edge_big.data();
      score = score_big.data();
      start = start_big.data();
    } else {
      edge = edge_small;
      score = score_small;
      start = start_small;
    }
  }
};

// The candidate starts of rank_patch_starts in increasing r into
// scratch.start, with their scores in scratch.score (score[i] belongs to
// start[i]), unsorted; returns their number. The scratch is prepared for
// used.size() faces. Raw arrays: a push_back per candidate cost more than
// the scoring of it.
uint32_t score_patch_starts_raw(const EditableMesh& mesh, uint32_t apex,
                                const std::vector<uint32_t>& star_ring,
                                const std::vector<uint8_t>& used, uint32_t k,
                                StartScratch& scratch);
// Larger score first, ties by r (stable insertion sort: runs are few).
inline void sort_patch_starts(uint32_t* out, size_t n, int64_t* score) {
  for (size_t i = 1; i < n; ++i) {
    const int64_t sc = score[i];
    const uint32_t r = out[i];
    size_t j = i;
    while (j > 0 && score[j - 1] < sc) {
      score[j] = score[j - 1];
      out[j] = out[j - 1];
      --j;
    }
    score[j] = sc;
    out[j] = r;
  }
}

inline void sort_patch_starts(std::vector<uint32_t>& out, int64_t* score) {
  sort_patch_starts(out.data(), out.size(), score);
}

}  // namespace meshstream
