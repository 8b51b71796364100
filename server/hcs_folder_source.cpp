// Catalog source: `.hcs` files served exactly as they are on disk.
#include <algorithm>
#include <filesystem>

#include "server/catalog.h"

namespace meshstream::server {
namespace {

namespace fs = std::filesystem;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

class HcsFolderSource final : public CatalogSource {
 public:
  explicit HcsFolderSource(std::string dir) : dir_(std::move(dir)) {}

  void load(Catalog& catalog, const CatalogLog& log) override {
    std::error_code ec;
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(dir_, ec)) {
      if (entry.is_regular_file() && lower(entry.path().extension().string()) == ".hcs") {
        files.push_back(entry.path());
      }
    }
    if (ec) {
      log("cannot list " + dir_ + ": " + ec.message());
      return;
    }
    std::sort(files.begin(), files.end());
    for (const fs::path& path : files) {
      const std::string name = path.stem().string();
      if (catalog.contains(name)) {
        log("skipped " + path.string() + ": model name '" + name + "' is taken");
        continue;
      }
      auto bytes = map_file(path.string());
      if (!bytes) {
        log("skipped " + bytes.error().message);
        continue;
      }
      auto model = make_model(name, "hcs", path.string(), std::move(*bytes));
      if (!model) {
        log("skipped " + model.error().message);
        continue;
      }
      (void)catalog.add(std::move(*model));
    }
  }

 private:
  std::string dir_;
};

}  // namespace

std::unique_ptr<CatalogSource> hcs_folder_source(std::string dir) {
  return std::make_unique<HcsFolderSource>(std::move(dir));
}

}  // namespace meshstream::server
