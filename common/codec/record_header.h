// The header of a structure record: u8 flags (kRecordStartsLayer or 0),
// varint walk steps, varint insertions, and in the embedded formats varint
// min shift. The range-coded block follows it (structure_record_reader.h).
#pragma once

#include <cstdint>
#include <vector>

#include "common/codec/stream_format.h"

namespace meshstream {

struct RecordHeader {
  bool starts_layer = false;
  uint32_t walk_steps = 0;
  uint32_t insertions = 0;
  uint32_t min_shift = 0;  // format 2 only
};
void write_record_header(const RecordHeader& header, std::vector<uint8_t>& out, uint8_t format = 2);

}  // namespace meshstream
