// Fuzz target: what the client does with a server's bytes: the
// ServerMessage frame reader of proto/framing.h with the client's limit,
// then the client's handling of each message as in
// client/stream_client.cpp (StreamClient::attempt): a header's facts are
// read (facts_from_header: either record index form, the compact one
// range-decoded) and it sets the resume point of the DecodedStream, a chunk at the expected offset
// is fed to it (the decoder that turns network bytes into the displayed mesh). StreamClient itself
// owns a socket, so the same calls are made directly.
//
// Input: the front is the byte stream from the "server", integers from the
// back choose the read sizes. Checked (trap on violation): no crash, no
// out-of-bounds or UB; the decoded record count never decreases, also
// when a chunk turns out bad.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "client/decoded_stream.h"
#include "client/stream_facts.h"
#include "proto/framing.h"

namespace {
void check(bool ok) {
  if (!ok) __builtin_trap();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace meshstream;
  FuzzedDataProvider provider(data, size);
  proto::ServerFrameReader reader(proto::kMaxServerFrameBytes);
  client::DecodedStream decoded;
  bool have_header = false;
  bool broken = false;
  uint64_t expected = 0;
  while (provider.remaining_bytes() > 0 && !broken) {
    const size_t n = provider.ConsumeIntegralInRange<size_t>(1, 1 + provider.remaining_bytes());
    std::vector<uint8_t> piece = provider.ConsumeBytes<uint8_t>(n);
    reader.feed(piece);
    while (!broken) {
      auto message = reader.next();
      if (!message) {
        broken = true;
        break;
      }
      if (!*message) break;
      const auto& m = **message;
      if (m.has_header()) {
        auto facts = client::facts_from_header(m.header());
        if (!facts) {
          broken = true;  // the client ends the run with the facts' error
          break;
        }
        check(facts->record_end.size() == facts->records_total);
        if (!decoded.resume_at(m.header().start_offset())) {
          broken = true;
          break;
        }
        expected = m.header().start_offset();
        have_header = true;
      } else if (m.has_chunk()) {
        if (!have_header || m.chunk().offset() != expected) {
          broken = true;
          break;
        }
        const std::string& bytes = m.chunk().data();
        const uint32_t before = decoded.records_decoded();
        auto fed = decoded.feed(
            std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()));
        if (!fed) {
          // Records completed before the bad one stay applied (last good state).
          check(decoded.records_decoded() >= before);
          broken = true;
          break;
        }
        check(decoded.records_decoded() >= before);
        expected += bytes.size();
        decoded.set_bytes_received(expected);
      } else if (m.has_end() || m.has_error()) {
        broken = true;
      }
    }
  }
  decoded.stop();
  return 0;
}
