// One model a server can stream: a `.hcs` stream held in memory (mapped or
// owned) with its parsed record index; the server never decodes geometry.
// Immutable once made and shared read-only (through shared_ptr) by every
// session on every thread; the changing set of models is ModelRegistry
// (model_registry.h).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "common/base/result.h"
#include "common/codec/container.h"
#include "server/compact_index.h"
#include "server/mapped_file.h"

namespace meshstream::server {

struct CatalogModel {
  std::string name;    // what clients ask for; never interpreted as a path
  std::string source;  // "hcs", "mesh" or "demo" (ModelInfo.source)
  std::string origin;  // file path or demo description, for logs
  std::shared_ptr<const StreamBytes> bytes;
  StreamIndex index;
  // The index coded once for StreamRequest.compact_index (empty coded: the
  // arrays are sent).
  CompactIndex compact;

  std::span<const uint8_t> stream() const { return bytes->bytes(); }
};

// Checks that `bytes` hold one complete, intact `.hcs` stream: the index
// parses, its total equals the byte count, every record's CRC matches.
// Also codes the index for compact headers (make_compact_index; a refusal
// is not an error). Errors name `origin`. O(bytes) for the CRCs.
Result<CatalogModel> make_model(std::string name, std::string source, std::string origin,
                                std::shared_ptr<const StreamBytes> bytes);

// How much a loading line matters: progress is info; a skipped input, a
// name clash or an unusable cache is a warning.
enum class CatalogLogLevel { kInfo, kWarn };
// Progress and problems while loading, one line each ("skipped x.ply: ...").
using CatalogLog = std::function<void(CatalogLogLevel level, const std::string& line)>;

// Whether this build can import and encode mesh files / make demo models
// (they need the mesh and codec modules' implementations).
bool mesh_encoding_available();
bool demo_models_available();

}  // namespace meshstream::server
