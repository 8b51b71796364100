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

struct RefinementModels {
  BitTreeModel<2> patch_count[8 * 2 * 3 * 4];  // by count_context; 3 = escape
  AdaptiveUIntModel patch_count_extra;
  BitTreeModel<4> start_rank[6];  // by min(k - 3, 5); 15 = escape
  AdaptiveUIntModel start_rank_big;
  BitTreeModel<4> valence[13];  // k - 3 (k <= 18), by min(apex ring size, 12)
  AdaptiveIntModel residual[kScaleContexts][3];
  AdaptiveUIntModel open_edge;  // 0 interior vertex, i+1: re-enters boundary edge i
  // Format 3 codes the structure symbols (counts, valences, ranks, open
  // edges) through models whose adaptation slows as they learn (BitModelV),
  // with finer contexts for valences and start ranks (valence_model3,
  // start_rank_context). Residuals keep `residual` (BitModelV there saved
  // 0.2 % of the stream but cost 2-3 % of decode time), plane records
  // GeometryModels, in every format.
  bool v_models = false;  // format >= 3: use the models below (set by the coders)
  BitTreeModel<2, BitModelV> patch_count3[8 * 2 * 3 * 4];  // by count_context
  AdaptiveUIntModelV patch_count_extra3;
  BitTreeModel<4, BitModelV> valence3[13 * 8];        // by valence_model3
  BitTreeModel<4, BitModelV> start_rank3[6 * 3 * 4];  // by start_rank_context
  AdaptiveUIntModelV start_rank_big3;
  AdaptiveUIntModelV open_edge3;
};

// The rank of a patch's start among rank_patch_starts' candidates.
void encode_start_rank(RefinementModels& m, RangeEncoder& enc, uint32_t k, uint32_t rank);
// Format 3: nothing when there is one candidate, else through the model of
// start_rank_context.
void encode_start_rank3(RefinementModels& m, RangeEncoder& enc, uint32_t context, size_t candidates,
                        uint32_t rank);
uint32_t decode_start_rank(RefinementModels& m, RangeDecoder& dec, uint32_t k);

// The decoder's bodies of decode_start_rank and of format 3's rank, forced
// inline into the structure record reader so its range decoder stays in
// registers (see MESHSTREAM_DECODE_INLINE in range_coder.h).
MESHSTREAM_DECODE_INLINE uint32_t decode_start_rank_inline(RefinementModels& m, RangeDecoder& dec,
                                                           uint32_t k) {
  const uint32_t rank = m.start_rank[std::min(k - 3, 5u)].decode(dec);
  return rank < 15 ? rank : 15 + m.start_rank_big.decode(dec);
}

MESHSTREAM_DECODE_INLINE uint32_t decode_start_rank_inline3(RefinementModels& m, RangeDecoder& dec,
                                                            uint32_t context) {
  const uint32_t rank = m.start_rank3[context].decode(dec);
  return rank < 15 ? rank : 15 + m.start_rank_big3.decode(dec);
}

}  // namespace meshstream
