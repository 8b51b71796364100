// The procedural demo models (common/mesh/procedural.h), encoded by the
// encoder pool and cached like mesh files; no folder needed.
#include "server/encode_cache.h"
#include "server/model_sources.h"

#if MESHSTREAM_HAVE_DEMO_MESH
#include "common/mesh/procedural.h"
#endif

namespace meshstream::server {
namespace {

EncodeTask demo_task(std::string name, std::string origin, std::string key,
                     std::function<Result<Mesh>()> make_mesh, const std::string& cache_dir) {
  EncodeTask task{name, "demo", origin, nullptr};
  const EncodeJob job{std::move(name), "demo", std::move(origin), std::move(key),
                      std::move(make_mesh)};
  task.run = [job, cache_dir](const EncodeProgressCallback& progress,
                              bool& from_cache) -> Result<CatalogModel> {
    EncodeOutcome outcome = encode_cached(job, cache_dir, progress);
    from_cache = outcome.from_cache;
    return std::move(outcome.model);
  };
  return task;
}

}  // namespace

bool demo_models_available() { return encoder_built() && MESHSTREAM_HAVE_DEMO_MESH != 0; }

std::vector<EncodeTask> demo_tasks(const std::string& cache_dir) {
  std::vector<EncodeTask> tasks;
#if MESHSTREAM_HAVE_DEMO_MESH
  if (!demo_models_available()) return tasks;
  // The trefoil at two sizes (the large one is ~100k vertices) and a torus;
  // the small ones first, so something is ready soon.
  tasks.push_back(demo_task(
      "torus", "demo torus 96x48", "demo-torus-96x48",
      []() -> Result<Mesh> { return make_torus(96, 48); }, cache_dir));
  for (const auto& [name, faces] : {std::pair<const char*, uint32_t>{"demo-small", 20000},
                                    std::pair<const char*, uint32_t>{"demo", 200000}}) {
    const uint32_t f = faces;
    tasks.push_back(demo_task(
        name, "demo trefoil, " + std::to_string(f) + " faces", "demo-trefoil-" + std::to_string(f),
        [f]() -> Result<Mesh> { return make_demo_mesh(f); }, cache_dir));
  }
#else
  (void)cache_dir;
#endif
  return tasks;
}

}  // namespace meshstream::server
