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
#include "common/codec/range_coder.h"
#include "common/codec/refinement_state.h"
#include "common/codec/stream_format.h"

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
  // Set by the scoring: the index of rank 0 and the runner-up's score.
  uint32_t best = 0;
  int64_t second = -1;
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
// the scoring of it. Also sets scratch.best (the index of the first of the
// largest scores: the stable sort's rank 0) and scratch.second (the
// largest score of the others, -1 when there is none).
uint32_t score_patch_starts_raw(const EditableMesh& mesh, uint32_t apex,
                                const std::vector<uint32_t>& star_ring,
                                const std::vector<uint8_t>& used, uint32_t k,
                                StartScratch& scratch);

// The squared lengths of the apex's edges to star ring entries 0 ..
// faces - 1 into scratch.edge, then the first min(faces, 14) again (a run's
// diagonals are read past the last face without a wrap test): what every
// k >= 4 score sums. The decoder computes them once per apex for all its
// patches. O(faces).
MESHSTREAM_DECODE_INLINE void apex_edge_lengths(const EditableMesh& mesh, uint32_t apex,
                                                const std::vector<uint32_t>& star_ring,
                                                uint32_t faces, StartScratch& scratch) {
  const Vec3i* p = mesh.positions().data();
  const Vec3i a = p[apex];
  const int64_t ax = a.x, ay = a.y, az = a.z;
  const uint32_t* ring = star_ring.data();
  int64_t* edge = scratch.edge;
  for (uint32_t i = 0; i < faces; ++i) {
    const Vec3i b = p[ring[i]];
    const int64_t dx = ax - b.x, dy = ay - b.y, dz = az - b.z;
    edge[i] = dx * dx + dy * dy + dz * dz;
  }
  const uint32_t wrap = faces < kMaxInsertedValence - 2 ? faces : kMaxInsertedValence - 2;
  for (uint32_t i = 0; i < wrap; ++i) edge[faces + i] = edge[i];
}

// score_patch_starts_raw for k >= 4 from the apex's edge lengths
// (apex_edge_lengths, same scratch): a sliding sum over the k-3 diagonals
// of each run (ring entries r+1 .. r+k-3), the best and second best kept on
// the way. `used` is read through a wrapped index only at the run's far end.
MESHSTREAM_DECODE_INLINE uint32_t score_runs_from_edges(const uint8_t* used, uint32_t faces,
                                                        bool boundary, uint32_t k,
                                                        StartScratch& scratch) {
  const uint32_t fan = k - 2;
  const int64_t* edge = scratch.edge;
  int64_t* score = scratch.score;
  uint32_t* out = scratch.start;
  const uint32_t last_start = boundary ? faces - fan : faces - 1;
  int64_t window = 0;
  for (uint32_t j = 1; j < fan; ++j) window += edge[j];
  uint32_t used_in_run = 0;
  for (uint32_t j = 0; j < fan; ++j) used_in_run += used[j];
  uint32_t far = fan < faces ? fan : 0;  // (r + fan) wrapped, maintained without division
  uint32_t n = 0, best = 0;
  int64_t best_score = -1, second = -1;
  for (uint32_t r = 0; r <= last_start; ++r) {
    if (used_in_run == 0) {
      // Strictly larger wins: ties keep the smaller r, as the stable sort.
      if (window > best_score) {
        second = best_score;
        best_score = window;
        best = n;
      } else if (window > second) {
        second = window;
      }
      score[n] = window;
      out[n++] = r;
    }
    // Slide the run one face on: drop face r and diagonal r+1, add the next.
    window += edge[r + fan] - edge[r + 1];
    used_in_run += used[far];
    used_in_run -= used[r];
    if (++far == faces) far = 0;
  }
  scratch.best = best;
  scratch.second = second;
  return n;
}

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
