#include "server/catalog.h"

namespace meshstream::server {

Result<CatalogModel> make_model(std::string name, std::string source, std::string origin,
                                std::shared_ptr<const StreamBytes> bytes) {
  const std::span<const uint8_t> stream = bytes->bytes();
  auto index = read_stream_index(stream);
  if (!index) return tl::unexpected(std::move(index.error()).with_context(origin));
  if (index->total_bytes() != stream.size()) {
    return make_error(ErrorCode::kCorrupt,
                      origin + ": index describes " + std::to_string(index->total_bytes()) +
                          " bytes but the stream has " + std::to_string(stream.size()));
  }
  for (size_t i = 0; i < index->records.size(); ++i) {
    const RecordEntry& r = index->records[i];
    if (!record_intact(r, stream.subspan(r.offset, r.size))) {
      return make_error(ErrorCode::kCorrupt,
                        origin + ": record " + std::to_string(i) + " fails its CRC-32 check");
    }
  }
  CatalogModel model;
  model.name = std::move(name);
  model.source = std::move(source);
  model.origin = std::move(origin);
  model.bytes = std::move(bytes);
  model.index = std::move(*index);
  model.compact = make_compact_index(model.index);
  return model;
}

}  // namespace meshstream::server
