// The models a server offers: immutable after start-up and shared read-only
// by every session on every thread. Each model is one `.hcs` stream held in
// memory (mapped or owned) with its parsed record index; the server never
// decodes geometry.
#pragma once

#include <functional>
#include <map>
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

class Catalog {
 public:
  // Adds `model` under model.name; kInvalidArgument when the name is taken.
  Status add(CatalogModel model);
  bool contains(std::string_view name) const { return models_.find(name) != models_.end(); }
  // Exact name match; nullptr for unknown names. O(log n).
  const CatalogModel* find(std::string_view name) const;
  // Every model, sorted by name.
  std::vector<const CatalogModel*> models() const;
  size_t size() const { return models_.size(); }

 private:
  std::map<std::string, CatalogModel, std::less<>> models_;
};

// How much a loading line matters: progress is info; a skipped input, a
// name clash or an unusable cache is a warning.
enum class CatalogLogLevel { kInfo, kWarn };
// Progress and problems while loading, one line each ("skipped x.ply: ...").
using CatalogLog = std::function<void(CatalogLogLevel level, const std::string& line)>;

// One way models enter the catalog: a folder of .hcs and mesh files, the
// procedural demo models. Sources are loaded in order; a name taken by an
// earlier source is not overwritten.
class CatalogSource {
 public:
  virtual ~CatalogSource() = default;
  // Adds what it can; reports every skipped input through `log` and never
  // fails as a whole because of one bad input.
  virtual void load(Catalog& catalog, const CatalogLog& log) = 0;
};

struct ModelsFolderOptions {
  std::string dir;
  // Where encoded streams are cached, keyed by content hash and
  // kEncoderVersion; an existing folder (prepare_cache_folder). Empty: no
  // cache (encode at every start).
  std::string cache_dir;
  unsigned threads = 0;  // 0 = one per core
};
// The files directly in `options.dir`, named as scan_models_folder says
// (models_folder.h): `.hcs` files served as-is (memory-mapped), mesh files
// (.ply .obj .stl .drc .off) imported and encoded at start-up on all cores,
// cached. Each skipped entry and each name clash is one warning.
std::unique_ptr<CatalogSource> models_folder_source(ModelsFolderOptions options);

// The procedural demo models (no folder needed): "demo" (trefoil, ~100k
// vertices), "demo-small" (~10k) and "torus", encoded at start-up and cached
// in `cache_dir` (empty = no cache).
std::unique_ptr<CatalogSource> demo_source(std::string cache_dir, unsigned threads = 0);

// Whether this build can import and encode mesh files / make demo models
// (they need the mesh and codec modules' implementations).
bool mesh_encoding_available();
bool demo_models_available();

}  // namespace meshstream::server
