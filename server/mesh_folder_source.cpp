// Catalog source: mesh files imported and encoded at start-up on all cores,
// cached by content hash and encoder version (encode_cache.h) so a second
// start maps the cache instead of encoding again.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/mesh/import.h"
#include "server/catalog.h"
#include "server/encode_cache.h"

namespace meshstream::server {
namespace {

namespace fs = std::filesystem;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

bool is_mesh_file(const fs::path& path) {
  const std::string ext = lower(path.extension().string());
  return ext == ".ply" || ext == ".obj" || ext == ".stl" || ext == ".drc" || ext == ".off";
}

// FNV-1a, 64 bits, over the file's bytes plus its size: a cache key, not a
// security measure.
Result<std::string> content_key(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return make_error(ErrorCode::kIo, path.string() + ": cannot read");
  uint64_t hash = 1469598103934665603ull;
  uint64_t size = 0;
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const auto n = static_cast<size_t>(in.gcount());
    for (size_t i = 0; i < n; ++i) {
      hash ^= static_cast<uint8_t>(buffer[i]);
      hash *= 1099511628211ull;
    }
    size += n;
  }
  char key[64];
  std::snprintf(key, sizeof key, "%016llx-%llu", static_cast<unsigned long long>(hash),
                static_cast<unsigned long long>(size));
  return std::string(key);
}

class MeshFolderSource final : public CatalogSource {
 public:
  explicit MeshFolderSource(MeshFolderOptions options) : options_(std::move(options)) {}

  void load(Catalog& catalog, const CatalogLog& log) override {
    std::error_code ec;
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(options_.dir, ec)) {
      if (entry.is_regular_file() && is_mesh_file(entry.path())) files.push_back(entry.path());
    }
    if (ec) {
      log("cannot list " + options_.dir + ": " + ec.message());
      return;
    }
    std::sort(files.begin(), files.end());
    // Names are fixed before encoding, in file order: the stem, or the whole
    // file name when the stem is taken (bunny.off and bunny.stl).
    std::vector<EncodeJob> jobs;
    auto is_taken = [&](const std::string& name) {
      return catalog.contains(name) ||
             std::any_of(jobs.begin(), jobs.end(),
                         [&](const EncodeJob& j) { return j.name == name; });
    };
    for (const fs::path& path : files) {
      std::string name = path.stem().string();
      if (is_taken(name)) name = path.filename().string();
      if (is_taken(name)) {
        log("skipped " + path.string() + ": model name '" + name + "' is taken");
        continue;
      }
      if (!encoder_built()) {
        log("skipped " + path.string() + ": this build cannot encode meshes (serve an .hcs)");
        continue;
      }
      auto key = content_key(path);
      if (!key) {
        log("skipped " + key.error().message);
        continue;
      }
      const std::string origin = path.string();
      jobs.push_back(EncodeJob{name, "mesh", origin, *key, [origin]() -> Result<Mesh> {
                                 auto imported = import_mesh(origin);
                                 if (!imported) return tl::unexpected(imported.error());
                                 return std::move(imported->mesh);
                               }});
    }
    encode_all(jobs, options_.cache_dir, options_.threads, catalog, log);
  }

 private:
  MeshFolderOptions options_;
};

}  // namespace

bool mesh_encoding_available() { return encoder_built(); }

std::unique_ptr<CatalogSource> mesh_folder_source(MeshFolderOptions options) {
  return std::make_unique<MeshFolderSource>(std::move(options));
}

}  // namespace meshstream::server
