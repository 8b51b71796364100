#include "client/stream_source.h"

#include <algorithm>

#include "client/client_options.h"
#include "client/http_stream_client.h"
#include "client/stream_client.h"

namespace meshstream::client {

std::unique_ptr<StreamSource> make_stream_source(const ClientOptions& o) {
  if (o.http) {
    HttpTarget target;
    target.url = *o.http;
    target.budget = o.budget;
    target.range_bytes = o.max_chunk_bytes;
    // A smaller request size asked for applies to the first request too.
    if (o.max_chunk_bytes)
      target.probe_bytes = std::min<uint64_t>(target.probe_bytes, o.max_chunk_bytes);
    target.reconnect = o.reconnect;
    return std::make_unique<SourceOf<HttpStreamClient>>(std::move(target));
  }
  StreamTarget target;
  target.host = o.host;
  target.port = o.port;
  target.model = o.model;
  target.budget = o.budget;
  target.max_chunk_bytes = o.max_chunk_bytes;
  target.reconnect = o.reconnect;
  target.wait = o.wait;
  return std::make_unique<SourceOf<StreamClient>>(std::move(target));
}

}  // namespace meshstream::client
