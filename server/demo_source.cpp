// Catalog source: the procedural demo models, encoded at start-up (no
// folder needed). Needs the mesh module's procedural meshes and the codec's
// encoder; a build without them serves no demo models and says so.
#include "server/catalog.h"

namespace meshstream::server {
namespace {

class DemoSource final : public CatalogSource {
 public:
  void load(Catalog& catalog, const CatalogLog& log) override {
    log("--demo: this build has no procedural demo models yet (common/mesh/procedural.h and "
        "the encoder are not built); serving files only");
  }
};

}  // namespace

bool demo_models_available() { return false; }

std::unique_ptr<CatalogSource> demo_source() { return std::make_unique<DemoSource>(); }

}  // namespace meshstream::server
