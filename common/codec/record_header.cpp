// Structure record headers: see record_header.h.
#include "common/codec/record_header.h"

#include "common/codec/byte_io.h"

namespace meshstream {

void write_record_header(const RecordHeader& header, std::vector<uint8_t>& out,
                         RefinementFormatInfo format) {
  out.push_back(header.starts_layer ? kRecordStartsLayer : 0);
  put_varint(out, header.walk_steps);
  put_varint(out, header.insertions);
  if (format.embedded) put_varint(out, header.min_shift);
}

}  // namespace meshstream
