// What one stream request sends, computed from the record index alone:
// where it starts (resume realigned down to a record boundary), where it
// ends (budget realigned down to a record boundary), and how the bytes in
// between are cut into chunks on record boundaries. Pure functions, no I/O;
// the rules are specified in proto/meshstream.proto (Budget, StreamRequest,
// Chunk).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "common/base/result.h"
#include "common/codec/budget.h"
#include "common/codec/container.h"
#include "proto/meshstream.pb.h"

namespace meshstream::server {

// The budget is the shared meshstream::Budget (common/codec/budget.h).
// From the wire's Budget: bytes (clamped to kMaxBudgetBytes: any budget past
// the end is the whole stream), vertices, percent (kPercentBytes),
// percent_vertices; kAll when no case is set. Values are not checked here
// (plan_stream does).
Budget budget_from_wire(const v1::Budget& wire);

// Records [first, end) of an index: one range of a ranged request
// (StreamRequest.records).
struct RecordSpan {
  uint32_t first = 0;
  uint32_t end = 0;
};

// At most this many ranges in one ranged request.
inline constexpr size_t kMaxRecordRanges = 4096;

struct StreamPlan {
  uint64_t start = 0;         // first byte sent (0 or a record's offset)
  uint64_t end = 0;           // one past the last byte sent (a record boundary)
  uint32_t first_record = 0;  // record starting at `start` (0 when start is 0)
  uint32_t end_record = 0;    // records [first_record, end_record) are sent
  bool complete = false;      // end is the end of the whole stream
  // A ranged request's ranges, in the order they are sent; empty for a
  // prefix. Then start/end and first_record/end_record are the first
  // range's start and the last range's end (StreamHeader), and `ranged_bytes`
  // what all ranges hold.
  std::vector<RecordSpan> ranges;
  std::vector<uint32_t> records_before;  // records in ranges [0, k), k = 0..ranges
  uint64_t ranged_bytes = 0;

  bool ranged() const { return !ranges.empty(); }
};

// A StreamRequest's plan: plan_stream for a prefix (resume offset and
// budget), plan_records for a ranged request (records set; combined with a
// resume offset or a budget it is kInvalidArgument).
Result<StreamPlan> plan_request(const StreamIndex& index, const v1::StreamRequest& request);

// The bytes a plan sends, in order: [start, end) for a prefix, one segment
// per range for a ranged plan (empty when nothing is sent).
struct ByteSegment {
  uint64_t start = 0;
  uint64_t end = 0;
};
std::vector<ByteSegment> plan_segments(const StreamIndex& index, const StreamPlan& plan);

// Resolves a request against `index`. kInvalidArgument for a budget value
// check_budget refuses (a percent outside (0, 100] or not finite); the
// message names the value. Never fails for offsets or budgets past the end
// (they are clamped). O(records): the end is the decoder's
// prefix_for_budget, so the server stops exactly where `meshstream decode`
// with the same budget does.
Result<StreamPlan> plan_stream(const StreamIndex& index, uint64_t resume_offset,
                               const Budget& budget);

// Resolves a ranged request (StreamRequest.records) against `index`.
// kInvalidArgument, its message naming the range and the problem, for an
// empty list, more than kMaxRecordRanges ranges, an empty or reversed range,
// a range past the last record, or two ranges sharing a record. The ranges
// are sent in the order given: the server trusts no order (the client's
// decoder refuses a record whose needs it lacks). O(ranges log ranges).
Result<StreamPlan> plan_records(const StreamIndex& index, std::span<const RecordSpan> ranges);

// Records [0, result) end at or before `offset`. O(log records).
uint32_t records_complete_at(const StreamIndex& index, uint64_t offset);

// Chunk.records_complete after sending up to `position` inside segment
// `segment` of plan_segments(plan): records_complete_at for a prefix; for a
// ranged plan the requested records sent whole, in request order.
// O(log records).
uint32_t records_sent_at(const StreamIndex& index, const StreamPlan& plan, size_t segment,
                         uint64_t position);

struct ChunkCut {
  uint64_t end;               // the chunk is [position, end)
  uint32_t records_complete;  // as Chunk.records_complete after it
};

// The next chunk from `position` (start <= position < plan.end), at most
// `max_chunk_bytes` (>= 1) long: whole records packed together (the
// container prefix counts as one unit), or one piece of a unit larger than
// the limit; a chunk that finishes a split unit ends there. O(records packed
// + log records).
ChunkCut next_chunk(const StreamIndex& index, const StreamPlan& plan, uint64_t position,
                    size_t max_chunk_bytes);
// The same inside one segment of plan_segments (a ranged plan's range):
// the chunk ends at or before segment.end. Its records_complete is the
// prefix count (records_sent_at gives a ranged plan's).
ChunkCut next_chunk(const StreamIndex& index, const ByteSegment& segment, uint64_t position,
                    size_t max_chunk_bytes);

}  // namespace meshstream::server
