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
// Checked invariants (a violation traps): chunks advance, stay inside the
// plan, end on the plan's end, records_complete never decreases.
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
  const Budget budget =
      request.has_budget() ? server::budget_from_wire(request.budget()) : Budget{};
  auto plan = server::plan_stream(index, request.resume_offset(), budget);
  if (!plan) return;
  check(plan->start <= plan->end && plan->end <= index.total_bytes());
  size_t chunk = request.max_chunk_bytes() ? request.max_chunk_bytes() : 64 * 1024;
  chunk = std::clamp<size_t>(chunk, 1024, 1 << 20);
  uint64_t position = plan->start;
  uint32_t records = server::records_complete_at(index, position);
  int steps = 0;
  while (position < plan->end) {
    const server::ChunkCut cut = server::next_chunk(index, *plan, position, chunk);
    check(cut.end > position && cut.end <= plan->end);
    check(cut.end - position <= chunk || cut.end - position <= index.payload_offset);
    check(cut.records_complete >= records && cut.records_complete <= index.records.size());
    records = cut.records_complete;
    position = cut.end;
    check(++steps < 1000000);
  }
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
