// Catalog source: the procedural demo models (common/mesh/procedural.h),
// encoded at start-up and cached like mesh files; no folder needed.
#include "server/catalog.h"
#include "server/encode_cache.h"

#if MESHSTREAM_HAVE_DEMO_MESH
#include "common/mesh/procedural.h"
#endif

namespace meshstream::server {
namespace {

class DemoSource final : public CatalogSource {
 public:
  DemoSource(std::string cache_dir, unsigned threads)
      : cache_dir_(std::move(cache_dir)), threads_(threads) {}

  void load(Catalog& catalog, const CatalogLog& log) override {
    if (!demo_models_available()) {
      log(CatalogLogLevel::kWarn,
          "--demo: this build has no procedural demo meshes or no encoder; serving files only");
      return;
    }
#if MESHSTREAM_HAVE_DEMO_MESH
    // The trefoil at two sizes (the large one is ~100k vertices) and a torus.
    struct Demo {
      const char* name;
      uint32_t faces;
    };
    std::vector<EncodeJob> jobs;
    for (const Demo demo : {Demo{"demo", 200000}, Demo{"demo-small", 20000}}) {
      if (catalog.contains(demo.name)) {
        log(CatalogLogLevel::kWarn,
            std::string("skipped demo model '") + demo.name + "': name is taken");
        continue;
      }
      const uint32_t faces = demo.faces;
      jobs.push_back(EncodeJob{demo.name, "demo",
                               "demo trefoil, " + std::to_string(faces) + " faces",
                               "demo-trefoil-" + std::to_string(faces),
                               [faces]() -> Result<Mesh> { return make_demo_mesh(faces); }});
    }
    if (catalog.contains("torus")) {
      log(CatalogLogLevel::kWarn, "skipped demo model 'torus': name is taken");
    } else {
      jobs.push_back(EncodeJob{"torus", "demo", "demo torus 96x48", "demo-torus-96x48",
                               []() -> Result<Mesh> { return make_torus(96, 48); }});
    }
    encode_all(jobs, cache_dir_, threads_, catalog, log);
#endif
  }

 private:
  std::string cache_dir_;
  unsigned threads_;
};

}  // namespace

bool demo_models_available() { return encoder_built() && MESHSTREAM_HAVE_DEMO_MESH != 0; }

std::unique_ptr<CatalogSource> demo_source(std::string cache_dir, unsigned threads) {
  return std::make_unique<DemoSource>(std::move(cache_dir), threads);
}

}  // namespace meshstream::server
