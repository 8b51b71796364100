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

Error too_many_ranges(size_t count) {
  return Error{ErrorCode::kInvalidArgument, "records: " + std::to_string(count) +
                                                " ranges, at most " +
                                                std::to_string(kMaxRecordRanges) + " a request"};
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

Result<StreamPlan> plan_records(const StreamIndex& index, std::span<const RecordSpan> ranges) {
  const auto count = static_cast<uint32_t>(index.records.size());
  auto refuse = [](std::string message) -> Result<StreamPlan> {
    return tl::unexpected(Error{ErrorCode::kInvalidArgument, std::move(message)});
  };
  if (ranges.empty()) return refuse("records: the list of ranges is empty");
  if (ranges.size() > kMaxRecordRanges) return tl::unexpected(too_many_ranges(ranges.size()));
  auto describe = [&](size_t i) {
    return "records.ranges[" + std::to_string(i) + "] [" + std::to_string(ranges[i].first) + ", " +
           std::to_string(ranges[i].end) + ")";
  };
  StreamPlan plan;
  for (size_t i = 0; i < ranges.size(); ++i) {
    const RecordSpan& r = ranges[i];
    if (r.end == r.first) return refuse(describe(i) + " is empty");
    if (r.end < r.first) return refuse(describe(i) + " is reversed (end before first)");
    if (r.end > count) {
      return refuse(describe(i) + " is out of bounds: the stream has " + std::to_string(count) +
                    " records, 0 to " + std::to_string(count - 1));
    }
    plan.ranged_bytes += record_end(index.records[r.end - 1]) - index.records[r.first].offset;
  }
  // Two ranges sharing a record: sort the positions by first, compare neighbours.
  std::vector<uint32_t> order(ranges.size());
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](uint32_t a, uint32_t b) { return ranges[a].first < ranges[b].first; });
  for (size_t k = 1; k < order.size(); ++k) {
    const uint32_t before = order[k - 1];
    const uint32_t after = order[k];
    if (ranges[after].first < ranges[before].end) {
      const uint32_t shared = ranges[after].first;
      return refuse(describe(std::min(before, after)) + " and " +
                    describe(std::max(before, after)) + " both ask for record " +
                    std::to_string(shared));
    }
  }
  plan.ranges.assign(ranges.begin(), ranges.end());
  plan.records_before.reserve(ranges.size() + 1);
  plan.records_before.push_back(0);
  for (const RecordSpan& r : ranges) {
    plan.records_before.push_back(plan.records_before.back() + (r.end - r.first));
  }
  plan.first_record = ranges.front().first;
  plan.end_record = ranges.back().end;
  plan.start = index.records[plan.first_record].offset;
  plan.end = record_end(index.records[plan.end_record - 1]);
  plan.complete = false;
  return plan;
}

Result<StreamPlan> plan_request(const StreamIndex& index, const v1::StreamRequest& request) {
  if (!request.has_records()) {
    const Budget budget = request.has_budget() ? budget_from_wire(request.budget()) : Budget{};
    return plan_stream(index, request.resume_offset(), budget);
  }
  if (request.resume_offset() != 0 || request.has_budget()) {
    return tl::unexpected(
        Error{ErrorCode::kInvalidArgument,
              "records cannot be combined with resume_offset or budget: a ranged request "
              "resumes by asking for the records still missing"});
  }
  const auto& wire = request.records().ranges();
  if (static_cast<size_t>(wire.size()) > kMaxRecordRanges) {
    return tl::unexpected(too_many_ranges(static_cast<size_t>(wire.size())));
  }
  std::vector<RecordSpan> ranges;
  ranges.reserve(static_cast<size_t>(wire.size()));
  for (const v1::RecordRange& r : wire) ranges.push_back({r.first(), r.end()});
  return plan_records(index, ranges);
}

std::vector<ByteSegment> plan_segments(const StreamIndex& index, const StreamPlan& plan) {
  std::vector<ByteSegment> segments;
  if (!plan.ranged()) {
    if (plan.start < plan.end) segments.push_back({plan.start, plan.end});
    return segments;
  }
  segments.reserve(plan.ranges.size());
  for (const RecordSpan& r : plan.ranges) {
    segments.push_back({index.records[r.first].offset, record_end(index.records[r.end - 1])});
  }
  return segments;
}

uint32_t records_sent_at(const StreamIndex& index, const StreamPlan& plan, size_t segment,
                         uint64_t position) {
  if (!plan.ranged()) return records_complete_at(index, position);
  if (segment >= plan.ranges.size()) return plan.records_before.back();
  const RecordSpan& r = plan.ranges[segment];
  const uint32_t whole = std::clamp(first_ending_after(index, position), r.first, r.end);
  return plan.records_before[segment] + (whole - r.first);
}

ChunkCut next_chunk(const StreamIndex& index, const StreamPlan& plan, uint64_t position,
                    size_t max_chunk_bytes) {
  return next_chunk(index, ByteSegment{plan.start, plan.end}, position, max_chunk_bytes);
}

ChunkCut next_chunk(const StreamIndex& index, const ByteSegment& segment, uint64_t position,
                    size_t max_chunk_bytes) {
  const uint64_t limit = std::min<uint64_t>(segment.end, position + max_chunk_bytes);
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
