// One record's entry in a stream's index: what the container (container.h)
// reads and writes and the compact index coder (record_index_coder.h) codes.
// Its own header so the two can share it without including each other.
#pragma once

#include <cstdint>

namespace meshstream {

// Version 3 records end in a CRC-32 of their payload.
inline constexpr uint32_t kRecordTrailerBytes = 4;
// The most records an index may list: absurd counts are refused before
// anything is allocated for them.
inline constexpr uint32_t kMaxRecords = 1u << 22;

struct RecordEntry {
  uint64_t offset = 0;    // from the start of the stream
  uint32_t size = 0;      // bytes in the stream (payload and trailer, if any)
  uint32_t vertices = 0;  // cumulative, after this record
  uint32_t faces = 0;
  // CRC-32 of the record's payload. Versions 1-2: from the index. Version 3:
  // the record's trailer as read_stream_index found it (0 when the record's
  // bytes were not in the span it read).
  uint32_t crc32 = 0;
  bool crc_trailer = false;  // version 3: the last 4 bytes are the CRC-32
};

}  // namespace meshstream
