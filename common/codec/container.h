// The `.hcs` container: everything a reader needs to find record boundaries
// without decoding geometry (the server serves bytes and never decodes).
//
// Layout (all integers little-endian):
//   offset 0   magic "MHCS" (4 bytes)
//          4   u16 format version (kContainerVersion), u16 flags (0)
//          8   u32 header_size H, then H header bytes (StreamHeader, see
//              container.cpp; fields added later go at the end, so a reader
//              skips what it does not know), then u32 CRC-32 of those H bytes
//   12+H+4     record index (version 2): u32 record_count, u32 L, then L
//              bytes: per record varint size, varint vertices added, zigzag
//              varint (2 * vertices added - faces added), u32 crc32; then a
//              u32 CRC-32 of count, L and
//              entries. (Version 1, still read: record_count entries of 24
//              bytes, u64 offset, u32 size, u32 vertices, u32 faces, u32
//              crc32, then the CRC.) Offsets follow from the sizes.
//   ...        record payloads, in index order, contiguous, record 0 first
// Record 0 is the base mesh. `vertices`/`faces` of a record are the counts of
// the mesh after applying it and all before it. Any prefix that ends on a
// record boundary decodes to a valid mesh.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream {

inline constexpr char kContainerMagic[4] = {'M', 'H', 'C', 'S'};
inline constexpr uint16_t kContainerVersion = 2;  // 1 (24-byte index entries) is still read
// Refuse absurd counts before allocating anything for them.
inline constexpr uint32_t kMaxRecords = 1u << 22;
inline constexpr uint32_t kMaxHeaderBytes = 1u << 16;

struct StreamHeader {
  uint32_t vertex_count = 0;  // of the full mesh
  uint32_t face_count = 0;
  uint32_t base_vertex_count = 0;
  uint32_t base_face_count = 0;
  BoundingBox bounds;         // quantization grid spans this box
  uint8_t quant_bits = 12;
  uint8_t base_coder = 0;       // which coder made record 0 (codec-defined ids)
  uint8_t structure_coder = 0;  // coder of refinement structure symbols
  uint8_t geometry_coder = 0;   // coder of refinement residuals
  uint32_t layer_count = 0;     // decimation layers in the stream
  std::vector<uint8_t> extra;   // header bytes this version does not interpret
};

struct RecordEntry {
  uint64_t offset = 0;  // from the start of the stream
  uint32_t size = 0;
  uint32_t vertices = 0;  // cumulative, after this record
  uint32_t faces = 0;
  uint32_t crc32 = 0;     // of the record's payload bytes
};

struct StreamIndex {
  StreamHeader header;
  std::vector<RecordEntry> records;
  uint64_t payload_offset = 0;  // where record 0 starts == bytes of magic+header+index
  uint64_t total_bytes() const {
    return records.empty() ? payload_offset : records.back().offset + records.back().size;
  }
};

// Serializes magic, header and index for records of the given payload sizes
// (offsets are filled in). Returns the bytes to put before the payloads.
std::vector<uint8_t> write_container_prefix(const StreamHeader& header,
                                            std::vector<RecordEntry>& records);

// Parses magic, header and index from the first bytes of a stream.
// Returns kTruncated when `prefix` is too short to hold them (feed more and
// call again), kParse/kCorrupt/kUnsupported/kLimit for a bad stream. Checks
// that records are contiguous and counts never decrease. O(records).
Result<StreamIndex> read_stream_index(std::span<const uint8_t> prefix);

// True when `payload` matches the record's checksum and size.
bool record_intact(const RecordEntry& record, std::span<const uint8_t> payload);

}  // namespace meshstream
