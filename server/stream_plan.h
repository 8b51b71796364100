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

struct StreamPlan {
  uint64_t start = 0;         // first byte sent (0 or a record's offset)
  uint64_t end = 0;           // one past the last byte sent (a record boundary)
  uint32_t first_record = 0;  // record starting at `start` (0 when start is 0)
  uint32_t end_record = 0;    // records [first_record, end_record) are sent
  bool complete = false;      // end is the end of the whole stream
};

// Resolves a request against `index`. kInvalidArgument for a budget value
// check_budget refuses (a percent outside (0, 100] or not finite); the
// message names the value. Never fails for offsets or budgets past the end
// (they are clamped). O(records): the end is the decoder's
// prefix_for_budget, so the server stops exactly where `meshstream decode`
// with the same budget does.
Result<StreamPlan> plan_stream(const StreamIndex& index, uint64_t resume_offset,
                               const Budget& budget);

// Records [0, result) end at or before `offset`. O(log records).
uint32_t records_complete_at(const StreamIndex& index, uint64_t offset);

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

}  // namespace meshstream::server
