// The compact form of StreamHeader.records (proto/meshstream.proto,
// RecordIndex.coded/count): a model's record sizes and cumulative counts
// coded once, when the model enters the catalog, with container version 3's
// index coder (common/codec/record_index_coder.h). Why: the four arrays cost
// about 12 bytes a record and come before the first mesh; coded, the bunny's
// 255 records take ~370 bytes instead of ~3 KB. Computed once per model,
// never per request: a header then copies a few hundred bytes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/codec/container.h"

namespace meshstream::server {

struct CompactIndex {
  // encode_record_index of every record: what RecordIndex.coded carries.
  // Empty when this model's index cannot be coded (see `refused`); its
  // headers then carry the arrays even to clients that asked for compact.
  std::vector<uint8_t> coded;
  // Why the coder refused the index (for the log); empty when coded.
  std::string refused;
};

// Codes `index.records` and checks that decode_record_index gives back
// exactly the same sizes, offsets and counts (a coder fault must not reach
// clients as a wrong index). Refused, for example, for a version 1/2
// stream with a record shorter than 4 bytes. O(records).
CompactIndex make_compact_index(const StreamIndex& index);

}  // namespace meshstream::server
