// ModelRegistry (server/model_registry.h): snapshots that keep a model's
// bytes alive after it is replaced or withdrawn, generations that make a
// superseded encode's result moot, counts per state, and the wire form.
#include "server/model_registry.h"

#include <gtest/gtest.h>

#include "server/synthetic_stream.h"

namespace meshstream::server {
namespace {

std::shared_ptr<const CatalogModel> synthetic_model(const std::string& name) {
  auto model = make_model(name, "hcs", name + ".hcs", own_bytes(make_synthetic_hcs({})));
  EXPECT_TRUE(model) << model.error().message;
  return std::make_shared<const CatalogModel>(std::move(*model));
}

ModelStatus status(const std::string& name, ModelState state,
                   std::shared_ptr<const CatalogModel> model = nullptr) {
  ModelStatus s;
  s.name = name;
  s.source = "mesh";
  s.origin = "/m/" + name + ".ply";
  s.state = state;
  s.model = std::move(model);
  return s;
}

TEST(ModelRegistry, ASnapshotKeepsItsModelsWhateverHappensLater) {
  ModelRegistry registry;
  registry.put(status("a", ModelState::kReady, synthetic_model("a")));
  const auto before = registry.snapshot();
  const std::weak_ptr<const CatalogModel> bytes = before->at("a").model;
  ASSERT_TRUE(registry.remove("a"));
  EXPECT_FALSE(registry.remove("a"));
  EXPECT_EQ(registry.snapshot()->count("a"), 0u);
  // The old snapshot (a running stream's) still holds the model.
  EXPECT_FALSE(bytes.expired());
  EXPECT_EQ(before->at("a").model->name, "a");
}

TEST(ModelRegistry, AnUpdateOfAReplacedEntryIsDropped) {
  ModelRegistry registry;
  const uint64_t first = registry.put(status("a", ModelState::kQueued));
  const uint64_t second = registry.put(status("a", ModelState::kQueued));
  EXPECT_NE(first, second);
  EXPECT_FALSE(registry.update("a", first, [](ModelStatus& s) { s.state = ModelState::kFailed; }));
  EXPECT_EQ(registry.snapshot()->at("a").state, ModelState::kQueued);
  EXPECT_TRUE(registry.update("a", second, [](ModelStatus& s) {
    s.state = ModelState::kEncoding;
    s.percent = 42;
  }));
  EXPECT_EQ(registry.snapshot()->at("a").state, ModelState::kEncoding);
  registry.remove("a");
  EXPECT_FALSE(registry.update("a", second, [](ModelStatus&) {}));
}

TEST(ModelRegistry, CountsEveryStateAndListsThemOnTheWire) {
  ModelRegistry registry;
  registry.put(status("q", ModelState::kQueued));
  auto e = status("e", ModelState::kEncoding);
  e.percent = 40;
  e.stage = "coding records";
  registry.put(e);
  registry.put(status("r", ModelState::kReady, synthetic_model("r")));
  auto f = status("f", ModelState::kFailed);
  f.reason = "/m/f.ply: line 3: not a number";
  registry.put(f);
  const StateCounts counts = registry.counts();
  EXPECT_EQ(counts.queued, 1u);
  EXPECT_EQ(counts.encoding, 1u);
  EXPECT_EQ(counts.ready, 1u);
  EXPECT_EQ(counts.failed, 1u);
  EXPECT_EQ(counts.total(), 4u);

  const auto snapshot = registry.snapshot();
  const v1::ModelInfo encoding = model_info(snapshot->at("e"));
  EXPECT_EQ(encoding.state(), v1::ModelInfo::ENCODING);
  EXPECT_EQ(encoding.percent(), 40);
  EXPECT_EQ(encoding.stage(), "coding records");
  EXPECT_EQ(encoding.stream_bytes(), 0u);
  const v1::ModelInfo failed = model_info(snapshot->at("f"));
  EXPECT_EQ(failed.state(), v1::ModelInfo::FAILED);
  EXPECT_EQ(failed.reason(), f.reason);
  const v1::ModelInfo ready = model_info(snapshot->at("r"));
  EXPECT_EQ(ready.state(), v1::ModelInfo::READY);
  EXPECT_EQ(ready.stream_bytes(), snapshot->at("r").model->stream().size());
  EXPECT_EQ(std::string(state_name(ModelState::kQueued)), "queued");
}

}  // namespace
}  // namespace meshstream::server
