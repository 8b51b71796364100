// Catalog source: mesh files imported and encoded at start-up, on all cores,
// with the encoded streams cached by content hash and encoder version so a
// second start maps the cache instead of encoding again.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>

#include <unistd.h>

#include "server/catalog.h"

#if MESHSTREAM_HAVE_MESH_ENCODER
#include "common/codec/encoder.h"
#include "common/mesh/import.h"
#endif

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

// FNV-1a, 64 bits, over the file's bytes: a cache key, not a security
// measure (the size is part of the key too).
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

struct Job {
  fs::path path;
  std::string name;
  Result<CatalogModel> result = make_error(ErrorCode::kIo, "not loaded");
  bool from_cache = false;
};

#if MESHSTREAM_HAVE_MESH_ENCODER
Result<CatalogModel> load_or_encode(Job& job, const std::string& cache_dir) {
  const std::string origin = job.path.string();
  auto key = content_key(job.path);
  if (!key) return tl::unexpected(key.error());
  const EncodeOptions options;
  const std::string cache_name = *key + "-q" + std::to_string(options.quant_bits) + "-e" +
                                 std::to_string(kEncoderVersion) + ".hcs";
  const fs::path cached = cache_dir.empty() ? fs::path() : fs::path(cache_dir) / cache_name;
  if (!cache_dir.empty() && fs::exists(cached)) {
    if (auto bytes = map_file(cached.string())) {
      if (auto model = make_model(job.name, "mesh", origin, std::move(*bytes))) {
        job.from_cache = true;
        return model;
      }
    }
    // A broken cache entry is re-encoded below and overwritten.
  }
  auto imported = import_mesh(origin);
  if (!imported) return tl::unexpected(imported.error());
  auto encoded = encode_hcs(imported->mesh, options);
  if (!encoded) return tl::unexpected(std::move(encoded.error()).with_context(origin));
  if (!cache_dir.empty()) {
    // Write then rename, so a concurrent or interrupted start never maps a
    // half-written file.
    const fs::path tmp = cached.string() + ".tmp" + std::to_string(::getpid());
    std::ofstream out(tmp, std::ios::binary);
    out.write(reinterpret_cast<const char*>(encoded->data()),
              static_cast<std::streamsize>(encoded->size()));
    out.close();
    std::error_code ec;
    if (out) fs::rename(tmp, cached, ec);
    if (out && !ec) {
      if (auto bytes = map_file(cached.string())) {
        return make_model(job.name, "mesh", origin, std::move(*bytes));
      }
    }
    fs::remove(tmp, ec);
  }
  return make_model(job.name, "mesh", origin, own_bytes(std::move(*encoded)));
}
#endif

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
    std::vector<Job> jobs;
    std::vector<std::string> taken;
    auto is_taken = [&](const std::string& name) {
      return catalog.contains(name) || std::find(taken.begin(), taken.end(), name) != taken.end();
    };
    for (const fs::path& path : files) {
      std::string name = path.stem().string();
      if (is_taken(name)) name = path.filename().string();
      if (is_taken(name)) {
        log("skipped " + path.string() + ": model name '" + name + "' is taken");
        continue;
      }
      taken.push_back(name);
      jobs.push_back(Job{path, name});
    }
    if (jobs.empty()) return;
    if (!mesh_encoding_available()) {
      for (const Job& job : jobs) {
        log("skipped " + job.path.string() +
            ": this build cannot import and encode meshes yet (serve an .hcs instead)");
      }
      return;
    }
#if MESHSTREAM_HAVE_MESH_ENCODER
    if (!options_.cache_dir.empty()) {
      fs::create_directories(options_.cache_dir, ec);
      if (ec) {
        log("cache " + options_.cache_dir + " unusable (" + ec.message() + "); encoding in memory");
        options_.cache_dir.clear();
      }
    }
    unsigned threads = options_.threads ? options_.threads : std::thread::hardware_concurrency();
    threads = std::max(1u, std::min<unsigned>(threads, static_cast<unsigned>(jobs.size())));
    std::atomic<size_t> next{0};
    std::atomic<size_t> done{0};
    std::mutex log_mutex;
    auto work = [&] {
      for (size_t i = next++; i < jobs.size(); i = next++) {
        const auto start = std::chrono::steady_clock::now();
        jobs[i].result = load_or_encode(jobs[i], options_.cache_dir);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::lock_guard lock(log_mutex);
        const size_t n = ++done;
        std::string line = "[" + std::to_string(n) + "/" + std::to_string(jobs.size()) + "] ";
        if (jobs[i].result) {
          char facts[160];
          std::snprintf(facts, sizeof facts, "%s %s: %u vertices, %zu bytes in %.2f s",
                        jobs[i].from_cache ? "from cache" : "encoded", jobs[i].path.c_str(),
                        jobs[i].result->index.header.vertex_count, jobs[i].result->stream().size(),
                        seconds);
          line += facts;
        } else {
          // Import and encode errors already name the file.
          line += "skipped: " + jobs[i].result.error().message;
        }
        log(line);
      }
    };
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (auto& t : pool) t.join();
    for (Job& job : jobs) {
      if (job.result) (void)catalog.add(std::move(*job.result));
    }
#endif
  }

 private:
  MeshFolderOptions options_;
};

}  // namespace

bool mesh_encoding_available() { return MESHSTREAM_HAVE_MESH_ENCODER != 0; }

std::unique_ptr<CatalogSource> mesh_folder_source(MeshFolderOptions options) {
  return std::make_unique<MeshFolderSource>(std::move(options));
}

}  // namespace meshstream::server
