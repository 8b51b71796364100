// The compact record index of container version 3 (container.h): per
// record the size, the vertices added and the face gap, range coded.
//
// Why: the index is the first thing a client receives and an embedded
// stream has hundreds of records, so at low rates its size competes with the
// base mesh (version 2's ~9-byte entries cost the bunny 2 KB before its
// 0.9 KB base). Consecutive records of one kind look alike — structure
// records are closed at about the same byte size and carry vertices in
// proportion to their bytes, plane records (no vertices) have similar sizes,
// faces added are nearly always twice the vertices added — so each field is
// coded as the difference from its prediction with adaptive Exp-Golomb
// models (range_coder.h): 1.3–2.0 bytes an entry on the real meshes.
//
// Coding, per record i (models persist across records):
//   i > 0: one bit "plane record" (vertices added == 0), context: whether
//          record i - 1 was one;
//   size:  record 0: size - 4, unsigned; else the signed difference from the
//          previous record of the same kind (structure, plane; the first of
//          a kind from 0), where a structure record under half the size of
//          its reference (a layer's short last record) leaves the reference
//          as it was;
//   dv:    record 0: vertices added, unsigned; structure record: signed
//          difference from size x (recent vertices / recent bytes) of
//          structure records (integer moving sums, decay 1/8);
//   gap:   2 dv - faces added, signed, one model per kind (usually 0).
// Sizes include each record's 4-byte CRC trailer.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "common/base/result.h"
#include "common/codec/record_entry.h"

namespace meshstream {

// Largest record size a version-3 index accepts (sizes count the trailer).
inline constexpr uint32_t kMaxRecordBytes = 1u << 30;
// An index of N records must code to at least N / kMaxRecordsPerIndexByte
// bytes: a hostile count cannot make the reader allocate much more than the
// bytes it was given. Real indexes use 1–2 bytes a record.
inline constexpr uint32_t kMaxRecordsPerIndexByte = 64;
// ...and at most this many bytes a record.
inline constexpr uint32_t kMaxIndexBytesPerRecord = 16;

// Codes `records` (size, vertices, faces used; sizes >= kRecordTrailerBytes,
// counts never decreasing, |2 x vertices added - faces added| <= 2^32).
// Returns at least one byte. kInvalidArgument when the list breaks those
// rules or would code outside the bounds above (the reader would refuse
// it). O(records).
Result<std::vector<uint8_t>> encode_record_index(std::span<const RecordEntry> records);

// Decodes `count` entries from exactly the bytes `coded` (all of them must be
// used; the range coder's dropped trailing zeros are allowed). Offsets start
// at `payload_offset`; every entry has crc_trailer set and crc32 0. kParse
// with the record named for anything out of bounds: size < 4 or > 1 GiB,
// counts above 2^32 - 1, faces removed, trailing or missing bytes.
// Checks count against coded.size() first and grows the list as entries
// decode (a hostile count fails before its memory is taken). O(count).
Result<std::vector<RecordEntry>> decode_record_index(std::span<const uint8_t> coded, uint32_t count,
                                                     uint64_t payload_offset);

}  // namespace meshstream
