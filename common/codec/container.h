// The `.hcs` container: everything a reader needs to find record boundaries
// without decoding geometry (the server serves bytes and never decodes).
//
// Layout (all integers little-endian):
//   offset 0   magic "MHCS" (4 bytes)
//          4   u16 format version (kContainerVersion, stream_format.h), u16 flags (0)
//          8   u32 header_size H, then H header bytes (StreamHeader, see
//              container.cpp; fields added later go at the end, so a reader
//              skips what it does not know), then u32 CRC-32 of those H bytes
//   12+H+4     record index (version 3): u32 record_count, u32 L, then L
//              range-coded bytes holding per record its size, vertices
//              added and (2 * vertices added - faces added), each predicted
//              from the records before it (record_index_coder.h, about 1.5
//              bytes a record); then a u32 CRC-32 of count, L and the bytes.
//              Offsets follow from the sizes.
//   ...        records, in index order, contiguous, record 0 first; each is
//              its payload followed by a u32 CRC-32 of that payload (the
//              trailer; a record's size counts it).
// Still read: version 2 (index entries varint size, varint vertices added,
// zigzag varint gap, u32 payload CRC-32; records are bare payloads) and
// version 1 (24-byte entries: u64 offset, u32 size, vertices, faces, CRC).
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
#include "common/codec/record_entry.h"
#include "common/codec/stream_format.h"
#include "common/mesh/mesh.h"

namespace meshstream {

inline constexpr char kContainerMagic[4] = {'M', 'H', 'C', 'S'};
// Refuse absurd sizes before allocating anything for them (kMaxRecords:
// record_entry.h).
inline constexpr uint32_t kMaxHeaderBytes = 1u << 16;

struct StreamHeader {
  uint32_t vertex_count = 0;  // of the full mesh
  uint32_t face_count = 0;
  uint32_t base_vertex_count = 0;
  uint32_t base_face_count = 0;
  BoundingBox bounds;  // quantization grid spans this box
  uint8_t quant_bits = 12;
  uint8_t base_coder = 0;       // which coder made record 0 (kBaseCoder*, stream_format.h)
  uint8_t structure_coder = 0;  // coder of refinement structure symbols
  uint8_t geometry_coder = 0;   // coder of refinement residuals
  uint32_t layer_count = 0;     // decimation layers in the stream
  std::vector<uint8_t> extra;   // header bytes this version does not interpret
};

struct StreamIndex {
  StreamHeader header;
  std::vector<RecordEntry> records;
  uint64_t payload_offset = 0;  // where record 0 starts == bytes of magic+header+index
  uint16_t version = 0;         // container version of the stream (1..kContainerVersion)
  uint64_t total_bytes() const {
    return records.empty() ? payload_offset : records.back().offset + records.back().size;
  }
};

// The header's H bytes as every container version writes them (the
// fixed fields, then `extra`); the u32 size before and the CRC-32 after
// them are the caller's.
std::vector<uint8_t> encode_stream_header(const StreamHeader& header);

// Serializes magic, header and a VERSION 2 index for records of the given
// payload sizes and CRCs (offsets are filled in). Returns the bytes to put
// before the payloads. Kept for tests and synthetic streams: version 2 stays
// readable. New streams use write_container.
std::vector<uint8_t> write_container_prefix(const StreamHeader& header,
                                            std::vector<RecordEntry>& records);

// Mesh counts after a record (cumulative), for write_container.
struct RecordCounts {
  uint32_t vertices = 0;
  uint32_t faces = 0;
};

struct WrittenContainer {
  std::vector<uint8_t> bytes;        // the whole stream
  std::vector<RecordEntry> records;  // as read_stream_index(bytes) returns them
  uint64_t payload_offset = 0;
};

// Writes a whole version-3 stream: magic, header, the compact index, and
// every payload followed by its CRC-32 trailer. `payloads` and `counts` have
// one entry per record, record 0 (the base) first. kInvalidArgument when the
// lengths differ, there are no records or more than kMaxRecords, a payload
// is over 1 GiB, counts decrease, or the last counts differ from the
// header's (anything read_stream_index would refuse). O(stream bytes).
Result<WrittenContainer> write_container(const StreamHeader& header,
                                         std::span<const std::vector<uint8_t>> payloads,
                                         std::span<const RecordCounts> counts);

// Parses magic, header and index from the first bytes of a stream.
// Returns kTruncated when `prefix` is too short to hold them (feed more and
// call again), kParse/kCorrupt/kUnsupported/kLimit for a bad stream. Checks
// that records are contiguous and counts never decrease. Version 3: fills
// each record's crc32 from its trailer when the record lies inside `prefix`
// (0 otherwise; not checked here: record_intact does). O(records).
Result<StreamIndex> read_stream_index(std::span<const uint8_t> prefix);

// True when `bytes` (the record's bytes in the stream, offset..offset+size)
// have the record's size and pass its checksum: version 3, the trailer
// matches the CRC-32 of the payload before it; versions 1-2, the index's CRC
// matches the bytes. O(size).
bool record_intact(const RecordEntry& record, std::span<const uint8_t> bytes);

// The payload of a record's bytes: without the trailer (version 3), else all
// of them. This is what the record decoders read. Precondition:
// bytes.size() == record.size (true once record_intact holds).
std::span<const uint8_t> record_payload(const RecordEntry& record, std::span<const uint8_t> bytes);

}  // namespace meshstream
