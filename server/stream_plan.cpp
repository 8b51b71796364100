#include "server/stream_plan.h"

#include <algorithm>
#include <charconv>
#include <cmath>
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

bool valid_percent(double p) { return std::isfinite(p) && p > 0 && p <= 100; }

tl::unexpected<Error> bad_percent(const std::string& what, double value) {
  // Shortest round-trip form: "nan", "-0", "101", "100.0000001" as sent.
  char shown[64];
  const auto end = std::to_chars(shown, shown + sizeof shown, value).ptr;
  return make_error(ErrorCode::kInvalidArgument,
                    what + " " + std::string(shown, end) + " is not in (0, 100]");
}

}  // namespace

uint32_t records_complete_at(const StreamIndex& index, uint64_t offset) {
  return first_ending_after(index, offset);
}

Result<StreamPlan> plan_stream(const StreamIndex& index, uint64_t resume_offset,
                               const Budget& budget) {
  const auto count = static_cast<uint32_t>(index.records.size());
  const uint64_t total = index.total_bytes();

  uint32_t end_record = count;
  if (const auto* b = std::get_if<ByteBudget>(&budget)) {
    end_record = records_within_bytes(index, b->bytes);
  } else if (const auto* v = std::get_if<VertexBudget>(&budget)) {
    auto it = std::upper_bound(index.records.begin(), index.records.end(), v->vertices,
                               [](uint32_t n, const RecordEntry& r) { return n < r.vertices; });
    end_record = std::max<uint32_t>(1, static_cast<uint32_t>(it - index.records.begin()));
  } else if (const auto* p = std::get_if<PercentBudget>(&budget)) {
    if (!valid_percent(p->percent)) return bad_percent("budget percent (of bytes)", p->percent);
    const auto bytes = static_cast<uint64_t>(std::floor(double(total) * p->percent / 100.0));
    end_record = records_within_bytes(index, bytes);
  } else if (const auto* pv = std::get_if<PercentVerticesBudget>(&budget)) {
    if (!valid_percent(pv->percent)) return bad_percent("budget percent_vertices", pv->percent);
    // The decoder's own rule, so the server ends exactly where
    // `meshstream decode --percent` does. It returns a record boundary.
    const uint64_t prefix =
        prefix_for_budget(index, DecodeBudget{DecodeBudget::Kind::kPercentVertices, pv->percent});
    end_record = records_within_bytes(index, prefix);
  }

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
