// See container_reseal.h; the layout is container.h's.
#include "common/codec/container_reseal.h"

#include "common/codec/byte_io.h"
#include "common/codec/container.h"
#include "common/codec/crc32.h"
#include "common/codec/record_index_coder.h"

namespace meshstream {
void reseal_checksums(std::vector<uint8_t>& s) {
  if (s.size() < 12) return;
  const uint16_t version = get_u16(s.data() + 4);
  const size_t header_size = get_u32(s.data() + 8);
  if (header_size > kMaxHeaderBytes || 12 + header_size + 8 > s.size()) return;
  set_u32(s.data() + 12 + header_size, crc32(0, s.data() + 12, header_size));
  const size_t count_at = 12 + header_size + 4;
  const size_t count = get_u32(s.data() + count_at);
  if (count == 0 || count > kMaxRecords) return;
  if (version == 1) {
    const size_t index_end = count_at + 4 + count * 24;
    if (index_end + 4 > s.size()) return;
    for (size_t i = 0; i < count; ++i) {
      const size_t e = count_at + 4 + i * 24;
      const uint64_t offset = get_u64(s.data() + e);
      const uint64_t size = get_u32(s.data() + e + 8);
      if (offset <= s.size() && size <= s.size() - offset)
        set_u32(s.data() + e + 20, crc32(0, s.data() + offset, size));
    }
    set_u32(s.data() + index_end, crc32(0, s.data() + count_at, index_end - count_at));
    return;
  }
  if (version == 3) {
    // The index CRC first (it does not cover the records), then every
    // trailer of a record the index locates; a mutated index that no longer
    // decodes leaves the records alone and fails in the reader.
    if (count_at + 8 > s.size()) return;
    const size_t length = get_u32(s.data() + count_at + 4);
    const size_t entries_at = count_at + 8;
    if (length > s.size() || entries_at + length + 4 > s.size()) return;
    const size_t index_end = entries_at + length;
    set_u32(s.data() + index_end, crc32(0, s.data() + count_at, index_end - count_at));
    auto records = decode_record_index(std::span<const uint8_t>(s.data() + entries_at, length),
                                       static_cast<uint32_t>(count), index_end + 4);
    if (!records) return;
    for (const RecordEntry& r : *records) {
      if (r.offset > s.size() || r.size > s.size() - r.offset) break;  // contiguous: the rest too
      const size_t payload = r.size - kRecordTrailerBytes;             // sizes are >= 4
      set_u32(s.data() + r.offset + payload, crc32(0, s.data() + r.offset, payload));
    }
    return;
  }
  if (count_at + 8 > s.size()) return;
  const size_t length = get_u32(s.data() + count_at + 4);
  const size_t entries_at = count_at + 8;
  if (length > s.size() || entries_at + length + 4 > s.size()) return;
  const size_t index_end = entries_at + length;
  uint64_t offset = index_end + 4;
  size_t pos = entries_at;
  // The reader's varints (32 bits at most): an entry it refuses ends the
  // resealing, as it ends the reader. pos counts from the stream start.
  const std::span<const uint8_t> entries(s.data(), index_end);
  for (size_t i = 0; i < count; ++i) {
    uint32_t size = 0, dv = 0, df = 0;
    if (!get_varint(entries, pos, size) || !get_varint(entries, pos, dv) ||
        !get_varint(entries, pos, df) || pos + 4 > index_end) {
      break;
    }
    if (offset <= s.size() && size <= s.size() - offset)
      set_u32(s.data() + pos, crc32(0, s.data() + offset, size));
    pos += 4;
    offset += size;
  }
  set_u32(s.data() + index_end, crc32(0, s.data() + count_at, index_end - count_at));
}

}  // namespace meshstream
