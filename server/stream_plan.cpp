#include "server/stream_plan.h"

#include <algorithm>
#include <string>

#include "common/codec/decoder.h"

namespace meshstream::server {
namespace {

uint64_t record_end(const RecordEntry& r) { return r.offset + r.size; }

// Index of the first record ending after `offset` (== records complete at offset).
uint32_t first_ending_after(const StreamIndex& index, uint64_t offset) {
  auto it = std::upper_bound(index.records.begin(), index.records.end(), offset,
                             [](uint64_t o, const RecordEntry& r) { return o < record_end(r); });
  return static_cast<uint32_t>(it - index.records.begin());
}

// Number of whole records within a byte prefix, at least 1 (the base mesh).
uint32_t records_within_bytes(const StreamIndex& index, uint64_t bytes) {
  return std::max<uint32_t>(1, first_ending_after(index, bytes));
}

// The wire field a budget came from, for INVALID_REQUEST messages.
const char* wire_name(Budget::Kind kind) {
  switch (kind) {
    case Budget::Kind::kBytes:
      return "budget bytes";
    case Budget::Kind::kVertices:
      return "budget vertices";
    case Budget::Kind::kPercentBytes:
      return "budget percent (of bytes)";
    case Budget::Kind::kPercentVertices:
      return "budget percent_vertices";
    case Budget::Kind::kAll:
    case Budget::Kind::kRatio:
      break;
  }
  return "budget";
}

}  // namespace

Budget budget_from_wire(const v1::Budget& wire) {
  switch (wire.limit_case()) {
    case v1::Budget::kBytes:
      return Budget::bytes(double(std::min<uint64_t>(wire.bytes(), kMaxBudgetBytes)));
    case v1::Budget::kVertices:
      return Budget::vertices(wire.vertices());
    case v1::Budget::kPercent:
      return Budget::percent_bytes(wire.percent());
    case v1::Budget::kPercentVertices:
      return Budget::percent_vertices(wire.percent_vertices());
    case v1::Budget::LIMIT_NOT_SET:
      break;
  }
  return Budget::all();
}

uint32_t records_complete_at(const StreamIndex& index, uint64_t offset) {
  return first_ending_after(index, offset);
}

Result<StreamPlan> plan_stream(const StreamIndex& index, uint64_t resume_offset,
                               const Budget& budget) {
  const auto count = static_cast<uint32_t>(index.records.size());
  const uint64_t total = index.total_bytes();

  if (auto valid = check_budget(budget, wire_name(budget.kind)); !valid) {
    return tl::unexpected(valid.error());
  }
  // The decoder's own rule, so the server ends exactly where `meshstream
  // decode` with the same budget does. It returns a record boundary.
  const uint32_t end_record = budget.kind == Budget::Kind::kAll
                                  ? count
                                  : records_within_bytes(index, prefix_for_budget(index, budget));

  StreamPlan plan;
  plan.end_record = end_record;
  plan.end = record_end(index.records[end_record - 1]);
  if (resume_offset >= index.payload_offset) {
    // The record containing resume_offset (or count when at/after the end).
    plan.first_record = first_ending_after(index, resume_offset);
    plan.start = plan.first_record < count ? index.records[plan.first_record].offset : total;
  }
  if (plan.start > plan.end) {  // resumed past the budget: nothing to send
    plan.end = plan.start;
    plan.end_record = plan.first_record;
  }
  plan.complete = plan.end == total;
  return plan;
}

ChunkCut next_chunk(const StreamIndex& index, const StreamPlan& plan, uint64_t position,
                    size_t max_chunk_bytes) {
  const uint64_t limit = std::min<uint64_t>(plan.end, position + max_chunk_bytes);
  // The unit `position` is in: the container prefix, or a record.
  uint32_t next = first_ending_after(index, position);  // record after the current unit
  uint64_t unit_start = 0;
  uint64_t unit_end = index.payload_offset;
  if (position >= index.payload_offset) {
    unit_start = index.records[next].offset;
    unit_end = record_end(index.records[next]);
    ++next;
  }
  if (unit_end > limit) {
    // Too large for one chunk (or cut by the plan's end, which is always a
    // boundary so only by the size limit): send a piece.
    return {limit, first_ending_after(index, limit)};
  }
  if (position != unit_start) {
    // The last piece of a split unit ends the chunk.
    return {unit_end, first_ending_after(index, unit_end)};
  }
  // Pack whole records after the unit while they fit; a chunk that
  // completes the base mesh (record 0) ends there: a client decodes a chunk
  // only once all of it has arrived, and the base is the first mesh it can
  // show (bunny at 8 KiB first chunks: 8.5 KB before the first mesh instead
  // of 1.8 KB, header included).
  uint64_t end = unit_end;
  const uint64_t base_end = index.records.empty() ? 0 : record_end(index.records[0]);
  while (end != base_end && next < index.records.size() &&
         record_end(index.records[next]) <= limit) {
    end = record_end(index.records[next]);
    ++next;
  }
  return {end, first_ending_after(index, end)};
}

}  // namespace meshstream::server
