#include "server/compact_index.h"

#include "common/codec/record_index_coder.h"

namespace meshstream::server {

CompactIndex make_compact_index(const StreamIndex& index) {
  CompactIndex out;
  auto coded = encode_record_index(index.records);
  if (!coded) {
    out.refused = coded.error().message;
    return out;
  }
  const auto count = static_cast<uint32_t>(index.records.size());
  auto decoded = decode_record_index(*coded, count, index.payload_offset);
  if (!decoded) {
    out.refused = "the coded index does not decode: " + decoded.error().message;
    return out;
  }
  for (uint32_t i = 0; i < count; ++i) {
    const RecordEntry& a = index.records[i];
    const RecordEntry& b = (*decoded)[i];
    if (a.offset != b.offset || a.size != b.size || a.vertices != b.vertices ||
        a.faces != b.faces) {
      out.refused = "the coded index decodes to a different record " + std::to_string(i);
      return out;
    }
  }
  out.coded = std::move(*coded);
  return out;
}

}  // namespace meshstream::server
