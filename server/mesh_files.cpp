// Mesh files imported and encoded by the encoder pool, cached by content
// hash and encoder version (encode_cache.h) so a second start maps the
// cache instead of encoding again.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/mesh/import.h"
#include "server/encode_cache.h"
#include "server/model_sources.h"

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

EncodeTask mesh_file_task(const ModelFile& file, const std::string& cache_dir) {
  EncodeTask task{file.name, "mesh", file.path, nullptr};
  task.run = [file, cache_dir](const EncodeProgressCallback& progress,
                               bool& from_cache) -> Result<CatalogModel> {
    if (!encoder_built()) {
      return make_error(ErrorCode::kUnsupported,
                        file.path + ": this build cannot encode meshes (serve an .hcs)");
    }
    // Hashed here, on the encoder thread: a big file costs a read.
    auto key = content_key(file.path);
    if (!key) return tl::unexpected(key.error());
    const std::string origin = file.path;
    const EncodeJob job{file.name, "mesh", origin, *key, [origin]() -> Result<Mesh> {
                          auto imported = import_mesh(origin);
                          if (!imported) return tl::unexpected(imported.error());
                          // What import could not carry, in the server log.
                          for (const std::string& note : imported->report.notes)
                            spdlog::warn("import {}: {}", origin, note);
                          return std::move(imported->mesh);
                        }};
    EncodeOutcome outcome = encode_cached(job, cache_dir, progress);
    from_cache = outcome.from_cache;
    return std::move(outcome.model);
  };
  return task;
}

bool mesh_encoding_available() { return encoder_built(); }

}  // namespace meshstream::server
