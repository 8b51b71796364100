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

Status Catalog::add(CatalogModel model) {
  if (contains(model.name)) {
    return make_error(ErrorCode::kInvalidArgument, "model name '" + model.name + "' is taken");
  }
  std::string name = model.name;
  models_.emplace(std::move(name), std::move(model));
  return {};
}

const CatalogModel* Catalog::find(std::string_view name) const {
  auto it = models_.find(name);
  return it == models_.end() ? nullptr : &it->second;
}

std::vector<const CatalogModel*> Catalog::models() const {
  std::vector<const CatalogModel*> out;
  out.reserve(models_.size());
  for (const auto& [name, model] : models_) out.push_back(&model);
  return out;
}

}  // namespace meshstream::server
