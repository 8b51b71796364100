// Mesh files imported and encoded at start-up on all cores, cached by
// content hash and encoder version (encode_cache.h) so a second start maps
// the cache instead of encoding again.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/mesh/import.h"
#include "server/encode_cache.h"
#include "server/folder_loaders.h"

namespace meshstream::server {
namespace {

namespace fs = std::filesystem;

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

}  // namespace

void encode_mesh_files(const std::vector<ModelFile>& files, const std::string& cache_dir,
                       unsigned threads, Catalog& catalog, const CatalogLog& log) {
  std::vector<EncodeJob> jobs;
  for (const ModelFile& file : files) {
    if (catalog.contains(file.name)) {
      log(CatalogLogLevel::kWarn,
          "skipped " + file.path + ": model name '" + file.name + "' is taken");
      continue;
    }
    if (!encoder_built()) {
      log(CatalogLogLevel::kWarn,
          "skipped " + file.path + ": this build cannot encode meshes (serve an .hcs)");
      continue;
    }
    auto key = content_key(file.path);
    if (!key) {
      log(CatalogLogLevel::kWarn, "skipped " + key.error().message);
      continue;
    }
    const std::string origin = file.path;
    jobs.push_back(EncodeJob{file.name, "mesh", origin, *key, [origin]() -> Result<Mesh> {
                               auto imported = import_mesh(origin);
                               if (!imported) return tl::unexpected(imported.error());
                               return std::move(imported->mesh);
                             }});
  }
  encode_all(jobs, cache_dir, threads, catalog, log);
}

bool mesh_encoding_available() { return encoder_built(); }

}  // namespace meshstream::server
