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
  // The embedded formats (2, 3) only: the coarsest shift an insertion of
  // the record starts with (insertion_prediction.h).
  uint32_t min_shift = 0;
};
// Appends the header as `format` has it (min_shift in the embedded formats).
void write_record_header(const RecordHeader& header, std::vector<uint8_t>& out,
                         RefinementFormatInfo format);

}  // namespace meshstream
