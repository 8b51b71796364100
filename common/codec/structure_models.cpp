// Start-rank coding: see structure_models.h.
#include "common/codec/structure_models.h"

namespace meshstream {

void encode_start_rank(RefinementModels& m, RangeEncoder& enc, uint32_t k, uint32_t rank) {
  BitTreeModel<4>& tree = m.start_rank[std::min(k - 3, 5u)];
  if (rank < 15) {
    tree.encode(enc, rank);
  } else {
    tree.encode(enc, 15);
    m.start_rank_big.encode(enc, rank - 15);
  }
}

void encode_start_rank_in_context(RefinementModels& m, RangeEncoder& enc, uint32_t context,
                                  size_t candidates, uint32_t rank) {
  if (candidates <= 1) return;
  BitTreeModel<4, FastStartBitModel>& tree = m.fast_start_start_rank[context];
  if (rank < 15) {
    tree.encode(enc, rank);
  } else {
    tree.encode(enc, 15);
    m.fast_start_start_rank_big.encode(enc, rank - 15);
  }
}

uint32_t decode_start_rank(RefinementModels& m, RangeDecoder& dec, uint32_t k) {
  return decode_start_rank_inline(m, dec, k);
}
}  // namespace meshstream
