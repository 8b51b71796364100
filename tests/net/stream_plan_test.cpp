// Stream planning on a synthetic index: budgets and resume land on record
// boundaries, chunks tile the range exactly and respect the size limit.
#include "server/stream_plan.h"

#include <gtest/gtest.h>

#include "server/synthetic_stream.h"
#include "server/token_bucket.h"

namespace meshstream::server {
namespace {

StreamIndex make_index(uint32_t records, uint64_t payload, uint32_t base_bytes = 5000) {
  SyntheticStreamOptions o;
  o.records = records;
  o.payload_bytes = payload;
  o.base_bytes = base_bytes;
  const std::vector<uint8_t> bytes = make_synthetic_hcs(o);
  auto index = read_stream_index(bytes);
  EXPECT_TRUE(index.has_value());
  EXPECT_EQ(index->total_bytes(), bytes.size());
  return *index;
}

uint64_t end_of(const StreamIndex& index, uint32_t record) {
  return index.records[record].offset + index.records[record].size;
}

TEST(StreamPlan, WholeStream) {
  const StreamIndex index = make_index(50, 400000);
  auto plan = plan_stream(index, 0, Budget::all());
  ASSERT_TRUE(plan);
  EXPECT_EQ(plan->start, 0u);
  EXPECT_EQ(plan->end, index.total_bytes());
  EXPECT_EQ(plan->first_record, 0u);
  EXPECT_EQ(plan->end_record, 50u);
  EXPECT_TRUE(plan->complete);
}

TEST(StreamPlan, ByteBudgetEndsAtLastBoundaryWithin) {
  const StreamIndex index = make_index(50, 400000);
  for (uint32_t r = 0; r < 49; ++r) {
    // Exactly at a boundary, and one byte short of the next.
    auto at = plan_stream(index, 0, Budget::bytes(end_of(index, r)));
    ASSERT_TRUE(at);
    EXPECT_EQ(at->end, end_of(index, r));
    EXPECT_EQ(at->end_record, r + 1);
    auto short_of = plan_stream(index, 0, Budget::bytes(end_of(index, r + 1) - 1));
    EXPECT_EQ(short_of->end, end_of(index, r));
    EXPECT_FALSE(short_of->complete);
  }
  // Less than the base mesh still gives the base mesh.
  EXPECT_EQ(plan_stream(index, 0, Budget::bytes(10))->end, end_of(index, 0));
  EXPECT_TRUE(plan_stream(index, 0, Budget::bytes(1ull << 40))->complete);
}

TEST(StreamPlan, VertexAndPercentBudgets) {
  const StreamIndex index = make_index(50, 400000);
  const uint32_t v = index.records[20].vertices;
  auto plan = plan_stream(index, 0, Budget::vertices(v));
  EXPECT_EQ(plan->end_record, 21u);
  EXPECT_EQ(plan_stream(index, 0, Budget::vertices(v - 1))->end_record, 20u);
  EXPECT_EQ(plan_stream(index, 0, Budget::vertices(0))->end_record, 1u);

  auto half = plan_stream(index, 0, Budget::percent_bytes(50));
  ASSERT_TRUE(half);
  EXPECT_LE(half->end, index.total_bytes() / 2);
  EXPECT_GT(end_of(index, half->end_record), index.total_bytes() / 2);
  EXPECT_TRUE(plan_stream(index, 0, Budget::percent_bytes(100))->complete);
  EXPECT_FALSE(plan_stream(index, 0, Budget::percent_bytes(0)).has_value());
  EXPECT_FALSE(plan_stream(index, 0, Budget::percent_bytes(100.5)).has_value());
  EXPECT_FALSE(plan_stream(index, 0, Budget::percent_bytes(std::nan(""))).has_value());
}

TEST(StreamPlan, ResumeRealignsDown) {
  const StreamIndex index = make_index(50, 400000);
  EXPECT_EQ(plan_stream(index, index.payload_offset - 1, {})->start, 0u);
  for (uint32_t r = 0; r < 50; ++r) {
    const uint64_t at = index.records[r].offset;
    auto exact = plan_stream(index, at, {});
    EXPECT_EQ(exact->start, at);
    EXPECT_EQ(exact->first_record, r);
    auto inside = plan_stream(index, at + index.records[r].size / 2, {});
    EXPECT_EQ(inside->start, at);
  }
  auto past = plan_stream(index, index.total_bytes() + 5, {});
  EXPECT_EQ(past->start, index.total_bytes());
  EXPECT_EQ(past->end, index.total_bytes());
  // Resumed beyond the budget: nothing to send.
  auto beyond = plan_stream(index, index.records[30].offset, Budget::bytes(end_of(index, 10)));
  EXPECT_EQ(beyond->start, beyond->end);
}

TEST(StreamPlan, ChunksTileTheRangeOnBoundaries) {
  // Large records (some above the chunk limit) and a big prefix.
  const StreamIndex index = make_index(300, 3000000, 100000);
  for (size_t max_chunk : {1024u, 4096u, 65536u}) {
    auto plan = plan_stream(index, 0, {});
    uint64_t position = plan->start;
    size_t chunks = 0;
    while (position < plan->end) {
      const ChunkCut cut = next_chunk(index, *plan, position, max_chunk);
      ASSERT_GT(cut.end, position);
      ASSERT_LE(cut.end - position, max_chunk);
      EXPECT_EQ(cut.records_complete, records_complete_at(index, cut.end));
      const bool boundary = cut.end == index.payload_offset ||
                            records_complete_at(index, cut.end) > 0 &&
                                end_of(index, records_complete_at(index, cut.end) - 1) == cut.end;
      if (!boundary) {
        // Only inside a unit larger than the limit.
        const uint32_t r = records_complete_at(index, cut.end);
        const uint64_t unit =
            cut.end < index.payload_offset ? index.payload_offset : index.records[r].size;
        EXPECT_GT(unit, max_chunk);
      }
      position = cut.end;
      ++chunks;
    }
    EXPECT_EQ(position, plan->end);
    EXPECT_GT(chunks, 1u);
  }
}

// The base mesh is the first mesh a client can show, and it decodes a chunk
// only once the whole chunk is there: the chunk that completes the base
// ends with it, even when later records would still fit. Later chunks pack.
TEST(StreamPlan, TheChunkThatCompletesTheBaseEndsThere) {
  const StreamIndex index = make_index(200, 60000, 1500);  // small records: many would fit
  auto plan = plan_stream(index, 0, {});
  ASSERT_TRUE(plan);
  const ChunkCut first = next_chunk(index, *plan, 0, 65536);
  EXPECT_EQ(first.end, end_of(index, 0));
  EXPECT_EQ(first.records_complete, 1u);
  const ChunkCut second = next_chunk(index, *plan, first.end, 65536);
  EXPECT_GT(second.records_complete, 2u) << "records after the base still pack together";
  // A prefix and base larger than the limit: the prefix alone, then the
  // base in pieces, the last piece ending at the base's end.
  uint64_t position = 0;
  ChunkCut cut;
  do {
    cut = next_chunk(index, *plan, position, 512);
    position = cut.end;
  } while (cut.records_complete == 0);
  EXPECT_EQ(cut.end, end_of(index, 0));
}

// A ranged request (StreamRequest.records): every bad list is refused with
// a message naming the range; a good one sends its ranges in the order
// given, each range's chunks tiling exactly its records.
TEST(StreamPlan, RangedRequestsRefuseBadRangesNamingThem) {
  const StreamIndex index = make_index(50, 400000);
  auto refused = [&](std::vector<RecordSpan> ranges) {
    auto plan = plan_records(index, ranges);
    EXPECT_FALSE(plan);
    return plan ? std::string("accepted") : plan.error().message;
  };
  EXPECT_EQ(refused({}), "records: the list of ranges is empty");
  EXPECT_EQ(refused({{0, 2}, {7, 7}}), "records.ranges[1] [7, 7) is empty");
  EXPECT_EQ(refused({{9, 4}}), "records.ranges[0] [9, 4) is reversed (end before first)");
  EXPECT_EQ(refused({{45, 51}}),
            "records.ranges[0] [45, 51) is out of bounds: the stream has 50 records, 0 to 49");
  EXPECT_EQ(refused({{50, 60}}),
            "records.ranges[0] [50, 60) is out of bounds: the stream has 50 records, 0 to 49");
  EXPECT_EQ(refused({{20, 30}, {1, 3}, {29, 31}}),
            "records.ranges[0] [20, 30) and records.ranges[2] [29, 31) both ask for record 29");
  EXPECT_EQ(refused({{5, 6}, {5, 6}}),
            "records.ranges[0] [5, 6) and records.ranges[1] [5, 6) both ask for record 5");
  EXPECT_EQ(refused(std::vector<RecordSpan>(kMaxRecordRanges + 1, {0, 1})),
            "records: 4097 ranges, at most 4096 a request");
  // At the limit, disjoint ranges are fine.
  const StreamIndex many = make_index(5000, 400000, 500);
  std::vector<RecordSpan> singles;
  for (uint32_t r = 0; r < kMaxRecordRanges; ++r) singles.push_back({r, r + 1});
  EXPECT_TRUE(plan_records(many, singles));
}

TEST(StreamPlan, RangedPlanSendsEachRangeWholeInTheOrderAsked) {
  const StreamIndex index = make_index(50, 400000);
  const std::vector<RecordSpan> ranges{{30, 33}, {2, 3}, {0, 1}, {40, 50}, {10, 20}};
  auto plan = plan_records(index, ranges);
  ASSERT_TRUE(plan) << plan.error().message;
  EXPECT_TRUE(plan->ranged());
  EXPECT_FALSE(plan->complete);
  EXPECT_EQ(plan->first_record, 30u);
  EXPECT_EQ(plan->end_record, 20u);
  const std::vector<ByteSegment> segments = plan_segments(index, *plan);
  ASSERT_EQ(segments.size(), ranges.size());
  uint64_t bytes = 0;
  uint32_t sent = 0;
  for (size_t k = 0; k < ranges.size(); ++k) {
    EXPECT_EQ(segments[k].start, index.records[ranges[k].first].offset);
    EXPECT_EQ(segments[k].end, end_of(index, ranges[k].end - 1));
    bytes += segments[k].end - segments[k].start;
    EXPECT_EQ(records_sent_at(index, *plan, k, segments[k].start), sent);
    // Chunks tile the segment; records_complete counts requested records.
    for (uint64_t position = segments[k].start; position < segments[k].end;) {
      const ChunkCut cut = next_chunk(index, segments[k], position, 3000);
      EXPECT_GT(cut.end, position);
      EXPECT_LE(cut.end, segments[k].end);
      const uint32_t now_sent = records_sent_at(index, *plan, k, cut.end);
      EXPECT_GE(now_sent, sent);
      EXPECT_LE(now_sent, sent + (ranges[k].end - ranges[k].first));
      sent = now_sent;
      position = cut.end;
    }
    EXPECT_EQ(records_sent_at(index, *plan, k, segments[k].end), plan->records_before[k + 1]);
  }
  EXPECT_EQ(plan->ranged_bytes, bytes);
  EXPECT_EQ(sent, 3u + 1 + 1 + 10 + 10);
  EXPECT_EQ(records_sent_at(index, *plan, ranges.size(), 0), sent);
}

TEST(TokenBucket, PacesToTheRate) {
  using Clock = TokenBucket::Clock;
  auto now = Clock::now();
  TokenBucket bucket(1000.0, 100.0, now);
  EXPECT_EQ(bucket.take(100, now), Clock::duration::zero());  // starts full
  const auto wait = bucket.take(500, now);                    // 500 in debt
  EXPECT_NEAR(std::chrono::duration<double>(wait).count(), 0.5, 1e-6);
  now += std::chrono::seconds(10);  // refill caps at the burst
  EXPECT_EQ(bucket.take(100, now), Clock::duration::zero());
  TokenBucket unlimited(0, 0, now);
  EXPECT_EQ(unlimited.take(1 << 30, now), Clock::duration::zero());
}

}  // namespace
}  // namespace meshstream::server
