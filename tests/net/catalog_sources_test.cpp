// The catalog sources through the real binary: mesh files encoded at start-up
// and cached (second start maps the cache), bad files reported and skipped,
// --demo models served with no folder.
#include <gtest/gtest.h>

#include <fstream>

#include "server/catalog.h"
#include "tests/net/greeted_client.h"
#include "tests/net/net_harness.h"
#include "tests/test_meshes.h"

namespace meshstream::nettest {
namespace {

namespace fs = std::filesystem;

std::string fresh_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("ms_cat_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

v1::ModelList list_models(uint16_t port) {
  TestClient c = greeted_client(port);
  v1::ServerMessage m;
  EXPECT_TRUE(c.list());
  EXPECT_EQ(c.read(m), ReadEnd::kMessage);
  return m.model_list();
}

// The streamed bytes of `model` equal one of the files in `cache`.
void expect_stream_equals_a_cache_file(uint16_t port, const std::string& model,
                                       const std::string& cache) {
  TestClient c;
  ASSERT_TRUE(c.connect(port));
  ASSERT_TRUE(c.hello());
  v1::ServerMessage m;
  ASSERT_EQ(c.read(m), ReadEnd::kMessage);
  ASSERT_TRUE(c.stream(model));
  const StreamResult r = read_stream(c);
  ASSERT_TRUE(r.ok) << r.problem;
  bool found = false;
  for (const auto& entry : fs::directory_iterator(cache))
    found |= read_file(entry.path()) == r.bytes;
  EXPECT_TRUE(found) << model << " is not byte-identical to any cached stream";
}

TEST(NetCatalog, MeshFilesAreEncodedCachedAndBadOnesSkipped) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  if (!server::mesh_encoding_available()) GTEST_SKIP() << "this build has no encoder";
  const std::string models = fresh_dir("meshes");
  const std::string cache = fresh_dir("cache");
  for (const char* name : {"sphere.obj", "fandisk.off", "inf_nan.obj"}) {
    fs::copy_file(testing::test_mesh(name), models + "/" + name);
  }
  std::string first_log;
  for (int start = 0; start < 2; ++start) {
    ServerProcess server;
    ASSERT_TRUE(server.start({"--models", models, "--cache", cache, "--threads", "2"},
                             models + "/../log" + std::to_string(start) + ".txt"))
        << server.log();
    const v1::ModelList list = list_models(server.port());
    ASSERT_EQ(list.models_size(), 3) << list.DebugString() << server.log();
    EXPECT_EQ(list.models(0).name(), "fandisk");
    EXPECT_EQ(list.models(0).source(), "mesh");
    EXPECT_EQ(list.models(0).state(), v1::ModelInfo::READY);
    EXPECT_EQ(list.models(0).vertices(), 6475u);
    // The bad file is listed as failed, its reason naming it and the problem.
    EXPECT_EQ(list.models(1).name(), "inf_nan");
    EXPECT_EQ(list.models(1).state(), v1::ModelInfo::FAILED);
    EXPECT_NE(list.models(1).reason().find(models + "/inf_nan.obj: "), std::string::npos)
        << list.models(1).reason();
    EXPECT_NE(list.models(1).reason().find("non-finite"), std::string::npos)
        << list.models(1).reason();
    EXPECT_EQ(list.models(2).name(), "sphere");
    EXPECT_EQ(list.models(2).state(), v1::ModelInfo::READY);
    expect_stream_equals_a_cache_file(server.port(), "fandisk", cache);
    const std::string log = server.log();
    EXPECT_NE(log.find("inf_nan.obj"), std::string::npos) << log;  // reported
    if (start == 0) {
      EXPECT_NE(log.find("encoded " + models + "/fandisk.off"), std::string::npos) << log;
    } else {
      EXPECT_NE(log.find("from cache " + models + "/fandisk.off"), std::string::npos) << log;
    }
  }
  std::error_code ec;
  fs::remove_all(fs::path(models).parent_path(), ec);
}

// Issue 18: glTF files are served; a truncated GLB is listed as failed
// with its reason, the rest served, and the import warnings are logged.
TEST(NetCatalog, GltfFilesAreServedAndABrokenOneFails) {
  MESHSTREAM_REQUIRE_TEST_MODELS();
  if (!server::mesh_encoding_available()) GTEST_SKIP() << "this build has no encoder";
  const std::string models = fresh_dir("gltf_models");
  const std::string cache = fresh_dir("gltf_cache");
  fs::copy_file(testing::test_model("Duck/Duck.glb"), models + "/duck.glb");
  const std::vector<uint8_t> bytes = read_file(testing::test_model("Duck/Duck.glb"));
  std::ofstream(models + "/broken.glb", std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size() / 2));
  ServerProcess server;
  ASSERT_TRUE(server.start({"--models", models, "--cache", cache, "--threads", "2"},
                           models + "/../log.txt"))
      << server.log();
  const v1::ModelList list = list_models(server.port());
  ASSERT_EQ(list.models_size(), 2) << list.DebugString() << server.log();
  EXPECT_EQ(list.models(0).name(), "broken");
  EXPECT_EQ(list.models(0).state(), v1::ModelInfo::FAILED);
  EXPECT_NE(list.models(0).reason().find(models + "/broken.glb: "), std::string::npos)
      << list.models(0).reason();
  EXPECT_NE(list.models(0).reason().find("truncated"), std::string::npos)
      << list.models(0).reason();
  EXPECT_EQ(list.models(1).name(), "duck");
  EXPECT_EQ(list.models(1).state(), v1::ModelInfo::READY);
  EXPECT_EQ(list.models(1).vertices(), 2108u);
  const std::string log = server.log();
  EXPECT_NE(log.find("camera(s) not carried"), std::string::npos) << log;
  std::error_code ec;
  fs::remove_all(fs::path(models).parent_path(), ec);
}

TEST(NetCatalog, DemoServesProceduralModelsWithoutAFolder) {
  if (!server::demo_models_available()) GTEST_SKIP() << "this build has no demo meshes";
  const std::string cache = fresh_dir("demo_cache");
  ServerProcess server;
  // The server encodes its three demo models in the background (start()
  // waits for them): a few seconds in a release build, up to a minute
  // under the sanitizers.
  ASSERT_TRUE(
      server.start({"--demo", "--cache", cache, "--threads", "2"}, cache + "/../demo.txt", 120s))
      << server.log();
  const v1::ModelList list = list_models(server.port());
  ASSERT_GE(list.models_size(), 1) << server.log();
  bool has_demo = false;
  for (const auto& model : list.models()) {
    EXPECT_EQ(model.source(), "demo");
    if (model.name() == "demo") {
      has_demo = true;
      EXPECT_GT(model.vertices(), 50000u);
    }
  }
  EXPECT_TRUE(has_demo) << list.DebugString();
  expect_stream_equals_a_cache_file(server.port(), "demo-small", cache);
  std::error_code ec;
  fs::remove_all(fs::temp_directory_path() / ("ms_cat_" + std::to_string(::getpid())), ec);
}

}  // namespace
}  // namespace meshstream::nettest
