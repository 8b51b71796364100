// Fuzz target: what the server does with a client's bytes before any
// socket write: the frame splitter and ClientMessage parser of
// proto/framing.h (as Session's reader uses them), then, for each stream
// request, the pure request handling of server/stream_plan.h against a real
// stream index (plan, then cut every chunk to the end as the writer does).
// Session::handle itself is private and needs a socket, so the plan/chunk
// functions it calls are driven directly, with the same clamping of
// max_chunk_bytes (server/session.cpp).
//
// Input layout: bytes from the FRONT are the byte stream, integers from the
// BACK (FuzzedDataProvider) choose the frame limit and read sizes.
// Ranged requests (StreamRequest.records) go through the same plan_request
// as the session's and are cut segment by segment.
// Checked invariants (a violation traps): chunks advance, stay inside their
// segment, end on its end, records_complete never decreases, a ranged plan
// sends exactly the bytes and records it announced.
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/codec/container.h"
#include "common/codec/encoder.h"
#include "common/mesh/procedural.h"
#include "proto/framing.h"
#include "server/stream_plan.h"

namespace {
using namespace meshstream;
namespace v1 = ::meshstream::v1;

void check(bool ok) {
  if (!ok) __builtin_trap();
}

// The index of a real multi-record stream, made once.
const StreamIndex& sample_index() {
  static const StreamIndex index = [] {
    auto stream = encode_hcs(make_icosphere(3));
    if (!stream) __builtin_trap();
    auto parsed = read_stream_index(*stream);
    if (!parsed) __builtin_trap();
    return *parsed;
  }();
  return index;
}

void handle_stream(const v1::StreamRequest& request) {
  const StreamIndex& index = sample_index();
  auto plan = server::plan_request(index, request);
  if (!plan) return;
  // A ranged plan's start and end are its first range's start and its last
  // range's end, in either order.
  check(plan->ranged() || plan->start <= plan->end);
  check(plan->start <= index.total_bytes() && plan->end <= index.total_bytes());
  check(plan->ranged() == request.has_records());
  size_t chunk = request.max_chunk_bytes() ? request.max_chunk_bytes() : 64 * 1024;
  chunk = std::clamp<size_t>(chunk, 1024, 1 << 20);
  const std::vector<server::ByteSegment> segments = server::plan_segments(index, *plan);
  uint32_t records = segments.empty()
                         ? server::records_complete_at(index, plan->start)
                         : server::records_sent_at(index, *plan, 0, segments.front().start);
  uint64_t bytes = 0;
  int steps = 0;
  for (size_t k = 0; k < segments.size(); ++k) {
    const server::ByteSegment& segment = segments[k];
    check(segment.start < segment.end && segment.end <= index.total_bytes());
    for (uint64_t position = segment.start; position < segment.end;) {
      const server::ChunkCut cut = server::next_chunk(index, segment, position, chunk);
      check(cut.end > position && cut.end <= segment.end);
      check(cut.end - position <= chunk || cut.end - position <= index.payload_offset);
      const uint32_t sent = server::records_sent_at(index, *plan, k, cut.end);
      check(sent >= records);
      check(plan->ranged() ? sent <= plan->records_before.back() : sent == cut.records_complete);
      check(sent <= index.records.size());
      records = sent;
      bytes += cut.end - position;
      position = cut.end;
      check(++steps < 1000000);
    }
  }
  // A ranged plan sends what it announced, every record of every range.
  if (plan->ranged()) check(bytes == plan->ranged_bytes && records == plan->records_before.back());
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider provider(data, size);
  const size_t limit = provider.ConsumeBool() ? proto::kDefaultMaxClientFrameBytes
                                              : provider.ConsumeIntegralInRange<size_t>(0, 4096);
  proto::ClientFrameReader reader(limit);
  proto::FrameSplitter splitter(limit);  // the raw splitter on the same bytes
  while (provider.remaining_bytes() > 0) {
    const size_t n = provider.ConsumeIntegralInRange<size_t>(1, 1 + provider.remaining_bytes());
    std::vector<uint8_t> piece = provider.ConsumeBytes<uint8_t>(n);
    reader.feed(piece);
    splitter.feed(piece);
    while (true) {
      auto frame = splitter.next();
      if (!frame) {
        check(!splitter.next().has_value());  // splitter errors are sticky (framing.h)
        break;
      }
      if (!*frame) break;
      check((*frame)->size() <= limit);
    }
    while (true) {
      auto message = reader.next();
      if (!message) return 0;  // the session sends an error frame and closes
      if (!*message) break;
      if ((*message)->has_stream()) handle_stream((*message)->stream());
      // Re-encoding a parsed message gives a frame the reader accepts again.
      std::vector<uint8_t> again = proto::encode_frame(**message);
      proto::ClientFrameReader echo(again.size() + 16);
      echo.feed(again);
      auto back = echo.next();
      check(back && *back);
    }
  }
  return 0;
}
