// The contexts of the structure symbols: which model codes a walk vertex's
// patch count, a patch's valence and its start rank, computed alike by
// encoder and decoder from the state before the symbol.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "common/codec/refinement_state.h"

namespace meshstream {

// Context of the patch count at walk vertex u: its free faces (capped at
// 7), whether the previous walk vertex held patches, u's age in layers
// (1, 2, 3+) and its valence (<= 5, 6, 7-8, 9+).
inline uint32_t count_context(const RefinementState& s, uint32_t u, uint32_t free_faces) {
  const uint32_t age = std::min<uint32_t>(s.layer - s.vertices[u].layer, 3) - 1;
  const uint32_t val = std::min<uint32_t>(s.vertices[u].valence, 12);
  const uint32_t vb = val <= 5 ? 0 : val == 6 ? 1 : val <= 8 ? 2 : 3;
  return ((std::min<uint32_t>(free_faces, 7) * 2 + (s.last_count > 0 ? 1 : 0)) * 3 + age) * 4 + vb;
}

// Format 3's model of the patch count: count_context's, adapting by
// FastStartBitModel (other contexts tried: docs/hcs-format.md, "Entropy
// coder").
inline BitTreeModel<2, FastStartBitModel>& fast_start_count_model(RefinementState& s, uint32_t u,
                                                                  uint32_t free_faces) {
  return s.models.fast_start_patch_count[count_context(s, u, free_faces)];
}

// Format 3's model of k - 3 for a patch at apex u: by u's ring size (as
// format 2) and the free faces of u left for it (min 7; k - 2 of them
// become the fan, after the patches already read at u).
inline BitTreeModel<4, FastStartBitModel>& fast_start_valence_model(RefinementState& s,
                                                                    uint32_t ring_size,
                                                                    uint32_t free_left) {
  return s.models
      .fast_start_valence[std::min(ring_size, 12u) * 8 + std::min<uint32_t>(free_left, 7)];
}

// Format 3's context of a start rank: k, the number of candidate runs
// (1 codes nothing) and how far the best run's score leads the second's.
// (candidates 2, 3-4, 5+; best/second below 1.25, 2, 4, or more).
// Scores are sums of at most 15 squared grid lengths (< 2^46 at 20 bits):
// the products cannot overflow.
inline uint32_t start_rank_context(uint32_t k, size_t candidates, int64_t best, int64_t second) {
  const uint32_t kb = std::min(k - 3, 5u);
  const uint32_t cb = candidates <= 2 ? 0 : candidates <= 4 ? 1 : 2;
  const uint32_t gap = 4 * best < 5 * second ? 0
                       : best < 2 * second   ? 1
                       : best < 4 * second   ? 2
                                             : 3;
  return (kb * 3 + cb) * 4 + gap;
}

}  // namespace meshstream
