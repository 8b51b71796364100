// What a StreamHeader tells the client (proto/meshstream.proto), as plain
// values: totals, the records this request sends, and every record's end
// offset and cumulative counts, read from whichever form of RecordIndex the
// server sent (the four arrays, or the compact coded form the client asks
// for with StreamRequest.compact_index).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/base/result.h"
#include "proto/meshstream.pb.h"

namespace meshstream::client {

namespace v1 = ::meshstream::v1;

// What the header said, kept from the first connection.
struct StreamFacts {
  std::string model;
  uint64_t total_bytes = 0;
  uint64_t start_offset = 0;
  uint64_t end_offset = 0;
  uint64_t payload_offset = 0;
  uint32_t end_record = 0;
  uint32_t records_total = 0;
  uint32_t vertices = 0;
  uint32_t faces = 0;
  uint32_t base_vertices = 0;
  uint32_t base_faces = 0;
  uint32_t quant_bits = 0;
  std::vector<uint64_t> record_end;       // stream offset after record i
  std::vector<uint32_t> record_vertices;  // cumulative, per record
  std::vector<uint32_t> record_faces;
};

// Reads `header`. Arrays form (RecordIndex.count == 0 and no coded bytes):
// read as the client always did, missing counts as 0. Compact form: the
// coded bytes must decode (decode_record_index) to exactly `count` records
// that start at payload_offset and end at total_bytes, with count >=
// end_record and the last record's counts equal to the header's vertices
// and faces, and the arrays must be empty. Anything else is kParse (does not
// decode) or kCorrupt (disagrees with the header), the message naming the
// model and the problem: a hostile server gets a clear error, never a crash
// or a huge allocation (count is bounded by kMaxRecords and by the coded
// size before anything is allocated). O(records).
Result<StreamFacts> facts_from_header(const v1::StreamHeader& header);

}  // namespace meshstream::client
