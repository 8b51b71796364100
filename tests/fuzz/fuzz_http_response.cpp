// Fuzz target: what the HTTP stream path does with a web server's bytes
// (client/http_response.h): the response reader (Beast's parser with the
// client's header limit) fed in pieces, the head checked against a range
// request as client/http_stream_client.cpp does (check_response, with the
// Content-Range parsed), then the URL and Content-Range parsers on their own.
//
// Input: the front is the byte stream from the "server", integers from the
// back choose the read sizes and the range asked for. Checked (trap on
// violation): no crash, no out-of-bounds or UB; body bytes reach the sink
// only after the head was accepted; a sink that refuses bytes (as the
// client refuses a body longer than its Content-Range) is never called
// again; leftover bytes are never more than what was fed.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "client/http_response.h"

namespace {
void check(bool ok) {
  if (!ok) __builtin_trap();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace meshstream::client;
  using meshstream::Status;
  FuzzedDataProvider provider(data, size);
  const uint64_t first = provider.ConsumeIntegralInRange<uint64_t>(0, 1 << 20);
  const bool open_ended = provider.ConsumeBool();
  const std::optional<uint64_t> last =
      open_ended
          ? std::nullopt
          : std::optional<uint64_t>(first + provider.ConsumeIntegralInRange<uint64_t>(0, 1 << 16));
  std::optional<BodyPlan> plan;
  bool head_seen = false;
  uint64_t body = 0;
  bool refused = false;
  HttpResponseReader reader(
      HttpLimits{},
      [&](const HttpResponseHead& head) -> Status {
        check(!head_seen);
        head_seen = true;
        auto checked = check_response(head, "http://fuzz/x.hcs", first, last, std::nullopt);
        if (!checked) return meshstream::make_error(checked.error().code, checked.error().message);
        plan = *checked;
        if (!head.content_range.empty()) (void)parse_content_range(head.content_range);
        return {};
      },
      [&](std::span<const uint8_t> bytes) -> Status {
        check(plan.has_value());
        check(!refused);
        body += bytes.size();
        if (plan->length && body > *plan->length) {
          refused = true;
          return meshstream::make_error(meshstream::ErrorCode::kParse, "longer than announced");
        }
        return {};
      });
  uint64_t fed = 0;
  bool ok = true;
  while (provider.remaining_bytes() > 0 && ok && !reader.done()) {
    const size_t n = provider.ConsumeIntegralInRange<size_t>(1, 1 + provider.remaining_bytes());
    std::vector<uint8_t> piece = provider.ConsumeBytes<uint8_t>(n);
    fed += piece.size();
    ok = static_cast<bool>(reader.feed(piece));
  }
  if (ok && !reader.done()) (void)reader.end_of_input();
  check(reader.leftover().size() <= fed);
  check(reader.body_bytes() == body);

  // The parsers on their own, on the same bytes as text.
  const std::string text(reinterpret_cast<const char*>(data), std::min<size_t>(size, 512));
  (void)parse_content_range(text);
  if (auto url = parse_http_url("http://" + text)) (void)range_request(*url, first, last);
  return 0;
}
