// The adaptive models of a refinement stream's symbols (range_coder.h):
// the structure symbols (patch counts, valences, start ranks, open edges) of
// both model families and the coarse residuals. RefinementState keeps one
// set across all records of a stream. Also the coding of a start rank
// through them (the rank's contexts: structure_contexts.h).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "common/codec/range_coder.h"

namespace meshstream {

inline constexpr int kScaleContexts = 20;

// The models of one stream. The structure symbols have two families:
// format 2's (BitModel, also format 1's) and format 3's (FastStartBitModel,
// the fast_start_ members, with finer valence and start-rank contexts:
// structure_contexts.h); RefinementFormatInfo::fast_start_structure_models
// says which one a stream uses. The coarse residuals use `residual` in
// every format, plane records GeometryModels (embedded_geometry.h); why the
// residuals stay with BitModel: docs/hcs-format.md, "Entropy coder".
struct RefinementModels {
  // Format 1 and 2 structure symbols, and the residuals.
  BitTreeModel<2> patch_count[8 * 2 * 3 * 4];  // by count_context; 3 = escape
  AdaptiveUIntModel patch_count_extra;
  BitTreeModel<4> start_rank[6];  // by min(k - 3, 5); 15 = escape
  AdaptiveUIntModel start_rank_big;
  BitTreeModel<4> valence[13];  // k - 3 (k <= 18), by min(apex ring size, 12)
  AdaptiveIntModel residual[kScaleContexts][3];
  AdaptiveUIntModel open_edge;  // 0 interior vertex, i+1: re-enters boundary edge i
  // Format 3 structure symbols.
  // True when the models below are in use: the encoder's switch, set from
  // the format it writes (the decoder picks by RefinementFormatInfo).
  bool use_fast_start_models = false;
  BitTreeModel<2, FastStartBitModel> fast_start_patch_count[8 * 2 * 3 * 4];  // by count_context
  FastStartUIntModel fast_start_patch_count_extra;
  BitTreeModel<4, FastStartBitModel> fast_start_valence[13 * 8];  // by fast_start_valence_model
  BitTreeModel<4, FastStartBitModel> fast_start_start_rank[6 * 3 * 4];  // by start_rank_context
  FastStartUIntModel fast_start_start_rank_big;
  FastStartUIntModel fast_start_open_edge;
};

// The rank of a patch's start among rank_patch_starts' candidates.
void encode_start_rank(RefinementModels& m, RangeEncoder& enc, uint32_t k, uint32_t rank);
// Format 3: by the rank's context (start_rank_context) instead of k;
// nothing when there is one candidate.
void encode_start_rank_in_context(RefinementModels& m, RangeEncoder& enc, uint32_t context,
                                  size_t candidates, uint32_t rank);
uint32_t decode_start_rank(RefinementModels& m, RangeDecoder& dec, uint32_t k);

// The decoder's bodies of decode_start_rank and of format 3's rank, forced
// inline into the structure record reader so its range decoder stays in
// registers (see MESHSTREAM_DECODE_INLINE in range_coder.h).
MESHSTREAM_DECODE_INLINE uint32_t decode_start_rank_inline(RefinementModels& m, RangeDecoder& dec,
                                                           uint32_t k) {
  const uint32_t rank = m.start_rank[std::min(k - 3, 5u)].decode(dec);
  return rank < 15 ? rank : 15 + m.start_rank_big.decode(dec);
}

MESHSTREAM_DECODE_INLINE uint32_t decode_start_rank_in_context_inline(RefinementModels& m,
                                                                      RangeDecoder& dec,
                                                                      uint32_t context) {
  const uint32_t rank = m.fast_start_start_rank[context].decode(dec);
  return rank < 15 ? rank : 15 + m.fast_start_start_rank_big.decode(dec);
}

}  // namespace meshstream
