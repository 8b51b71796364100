#include "server/encode_cache.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include "server/cache_lock.h"

#if MESHSTREAM_HAVE_MESH_ENCODER
#include "common/codec/encoder.h"
#endif

namespace meshstream::server {

namespace fs = std::filesystem;

bool encoder_built() { return MESHSTREAM_HAVE_MESH_ENCODER != 0; }

EncodeOutcome encode_cached(const EncodeJob& job, const std::string& cache_dir,
                            const EncodeProgressCallback& progress) {
  EncodeOutcome out;
  const auto start = std::chrono::steady_clock::now();
  auto finish = [&](Result<CatalogModel> model) {
    out.model = std::move(model);
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
  };
#if MESHSTREAM_HAVE_MESH_ENCODER
  EncodeOptions options;
  options.progress = progress;
  const fs::path cached =
      cache_dir.empty()
          ? fs::path()
          : fs::path(cache_dir) / (job.key + "-q" + std::to_string(options.quant_bits) + "-e" +
                                   std::to_string(kEncoderVersion) + ".hcs");
  auto map_cached = [&]() -> std::optional<Result<CatalogModel>> {
    if (cache_dir.empty() || !fs::exists(cached)) return std::nullopt;
    if (auto bytes = map_file(cached.string())) {
      if (auto model = make_model(job.name, job.source, job.origin, std::move(*bytes))) {
        out.from_cache = true;
        return model;
      }
    }
    return std::nullopt;  // a broken cache entry is re-encoded below and replaced
  };
  if (auto model = map_cached()) return finish(std::move(*model));
  // Servers sharing the cache folder encode each entry once: the first to
  // take the entry's lock encodes, the others wait and then map its file.
  // Without the lock (a read-only folder) temp + rename still keeps it whole.
  std::optional<CacheEntryLock> lock;
  if (!cache_dir.empty()) {
    if (auto taken = CacheEntryLock::acquire(cached.string())) lock.emplace(std::move(*taken));
    if (auto model = map_cached()) return finish(std::move(*model));
  }
  auto mesh = job.make_mesh();
  if (!mesh) return finish(tl::unexpected(mesh.error()));
  auto encoded = encode_hcs(*mesh, options);
  if (!encoded) return finish(tl::unexpected(std::move(encoded.error()).with_context(job.origin)));
  // What the stream does not carry goes to the log, never dropped in silence.
  for (const std::string& w : encode_warnings(*mesh))
    std::fprintf(stderr, "meshstream-server: %s: warning: %s\n", job.origin.c_str(), w.c_str());
  if (!cache_dir.empty()) {
    // Write then rename, so a concurrent or interrupted start never maps a
    // half-written file.
    const fs::path tmp = cached.string() + ".tmp" + std::to_string(::getpid());
    std::ofstream file(tmp, std::ios::binary);
    file.write(reinterpret_cast<const char*>(encoded->data()),
               static_cast<std::streamsize>(encoded->size()));
    file.close();
    std::error_code ec;
    if (file) fs::rename(tmp, cached, ec);
    if (file && !ec) {
      if (auto bytes = map_file(cached.string())) {
        return finish(make_model(job.name, job.source, job.origin, std::move(*bytes)));
      }
    }
    fs::remove(tmp, ec);
  }
  return finish(make_model(job.name, job.source, job.origin, own_bytes(std::move(*encoded))));
#else
  (void)cache_dir;
  (void)progress;
  return finish(make_error(ErrorCode::kUnsupported,
                           job.origin + ": this build cannot encode meshes (no encoder)"));
#endif
}

Result<bool> prepare_cache_folder(const std::string& dir, bool create_parents) {
  std::error_code ec;
  const fs::path path(dir);
  // One look at the path: servers started together race to create the
  // folder, and asking "a folder?" then "exists?" sees it appear between
  // the two questions.
  const fs::file_status status = fs::status(path, ec);
  if (fs::is_directory(status)) return false;
  if (fs::exists(status)) {
    return make_error(ErrorCode::kInvalidArgument, dir + " exists and is not a folder");
  }
  // "x/" names the folder x: its parent is that of x.
  const fs::path parent = (path.has_filename() ? path : path.parent_path()).parent_path();
  if (!create_parents && !parent.empty() && !fs::is_directory(parent, ec)) {
    return make_error(ErrorCode::kInvalidArgument,
                      dir + ": its parent folder " + parent.string() +
                          " does not exist (the server creates only the last level of a cache "
                          "path)");
  }
  if (create_parents) {
    fs::create_directories(path, ec);
  } else {
    fs::create_directory(path, ec);
  }
  if (ec) return make_error(ErrorCode::kIo, dir + ": cannot create it: " + ec.message());
  return true;
}

}  // namespace meshstream::server
