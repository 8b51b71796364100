// Catalog source: a --models folder. Scans it once (names fixed before any
// file is loaded, so the naming never depends on which encode finishes
// first), warns about every entry it skips and every name clash, then serves
// the .hcs files and encodes the mesh files.
#include "server/folder_loaders.h"
#include "server/models_folder.h"

namespace meshstream::server {
namespace {

class ModelsFolderSource final : public CatalogSource {
 public:
  explicit ModelsFolderSource(ModelsFolderOptions options) : options_(std::move(options)) {}

  void load(Catalog& catalog, const CatalogLog& log) override {
    auto scan = scan_models_folder(options_.dir);
    if (!scan) {
      log(CatalogLogLevel::kWarn, scan.error().message);
      return;
    }
    for (const SkippedEntry& skipped : scan->skipped) {
      log(CatalogLogLevel::kWarn, "skipped " + skipped.path + ": " + skipped.reason);
    }
    for (const NameClash& clash : scan->clashes) log(CatalogLogLevel::kWarn, describe(clash));
    add_hcs_files(scan->hcs, catalog, log);
    encode_mesh_files(scan->meshes, options_.cache_dir, options_.threads, catalog, log);
  }

 private:
  ModelsFolderOptions options_;
};

}  // namespace

std::unique_ptr<CatalogSource> models_folder_source(ModelsFolderOptions options) {
  return std::make_unique<ModelsFolderSource>(std::move(options));
}

}  // namespace meshstream::server
