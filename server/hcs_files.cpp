// `.hcs` files served exactly as they are on disk.
#include "server/folder_loaders.h"

namespace meshstream::server {

void add_hcs_files(const std::vector<ModelFile>& files, Catalog& catalog, const CatalogLog& log) {
  for (const ModelFile& file : files) {
    if (catalog.contains(file.name)) {
      log(CatalogLogLevel::kWarn,
          "skipped " + file.path + ": model name '" + file.name + "' is taken");
      continue;
    }
    auto bytes = map_file(file.path);
    if (!bytes) {
      log(CatalogLogLevel::kWarn, "skipped " + bytes.error().message);
      continue;
    }
    auto model = make_model(file.name, "hcs", file.path, std::move(*bytes));
    if (!model) {
      log(CatalogLogLevel::kWarn, "skipped " + model.error().message);
      continue;
    }
    (void)catalog.add(std::move(*model));
  }
}

}  // namespace meshstream::server
