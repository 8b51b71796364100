// The two mesh subcommands as a user runs them: `meshstream generate` and
// `meshstream info` on a mesh file (exit codes 0 / 1 / 2, JSON fields).
// Skipped when the meshstream binary has not been built.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/test_meshes.h"

namespace meshstream {
namespace {

std::string binary() {
#ifdef MESHSTREAM_BINARY_DIR
  const std::string path = std::string(MESHSTREAM_BINARY_DIR) + "/tools/meshstream";
  if (std::filesystem::exists(path)) return path;
#endif
  return {};
}

struct CommandResult {
  int exit_code = -1;
  std::string out;
};

CommandResult run(const std::string& args) {
  CommandResult r;
  FILE* pipe = ::popen((binary() + " " + args + " 2>/dev/null").c_str(), "r");
  if (!pipe) return r;
  char buffer[4096];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) r.out.append(buffer, n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

#define REQUIRE_BINARY()                                                   \
  do {                                                                     \
    if (binary().empty()) GTEST_SKIP() << "tools/meshstream is not built"; \
  } while (0)

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("meshstream_cmd_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

TEST(MeshCommands, GenerateThenInfoReportsTheDemoTopology) {
  REQUIRE_BINARY();
  const std::string path = temp_path("demo.ply");
  const CommandResult generated = run("generate demo -o " + path + " --size 3000");
  ASSERT_EQ(generated.exit_code, 0) << generated.out;
  const CommandResult info = run("info --json " + path);
  std::filesystem::remove(path);
  ASSERT_EQ(info.exit_code, 0);
  const auto json = nlohmann::json::parse(info.out);
  EXPECT_EQ(json["mesh"]["genus"], 1);
  EXPECT_EQ(json["mesh"]["components"], 1);
  EXPECT_EQ(json["mesh"]["boundary_edges"], 0);
  EXPECT_EQ(json["mesh"]["manifold"], true);
  EXPECT_EQ(json["import"]["changed"], false);
  EXPECT_NEAR(json["mesh"]["faces"].get<double>(), 3000, 150);
}

TEST(MeshCommands, EveryShapeCanBeGenerated) {
  REQUIRE_BINARY();
  for (const char* shape : {"icosahedron", "icosphere", "grid", "components", "torus"}) {
    const std::string path = temp_path(std::string(shape) + ".obj");
    const CommandResult r = run(std::string("generate ") + shape + " -o " + path);
    EXPECT_EQ(r.exit_code, 0) << shape;
    EXPECT_TRUE(std::filesystem::exists(path)) << shape;
    std::filesystem::remove(path);
  }
}

TEST(MeshCommands, InfoShowsWhatImportRepaired) {
  REQUIRE_BINARY();
  MESHSTREAM_REQUIRE_TEST_MESHES();
  const CommandResult info = run("info --json " + testing::test_mesh("suzanne.obj"));
  ASSERT_EQ(info.exit_code, 0);
  const auto json = nlohmann::json::parse(info.out);
  EXPECT_EQ(json["file"]["nonmanifold_vertices"], 2);
  EXPECT_EQ(json["file"]["manifold"], false);
  EXPECT_TRUE(json["file"]["genus"].is_null());
  EXPECT_EQ(json["import"]["welded_vertices"], 2);
  EXPECT_EQ(json["import"]["split_vertices"], 2);
  EXPECT_EQ(json["mesh"]["manifold"], true);
  const CommandResult text = run("info " + testing::test_mesh("suzanne.obj"));
  EXPECT_EQ(text.exit_code, 0);
  EXPECT_NE(text.out.find("split vertices"), std::string::npos) << text.out;
}

TEST(MeshCommands, BadDataExitsOneAndBadUsageTwo) {
  REQUIRE_BINARY();
  EXPECT_EQ(run("info /nonexistent/mesh.obj").exit_code, 1);
  if (!testing::test_mesh_dir().empty()) {
    EXPECT_EQ(run("info " + testing::test_mesh("inf_nan.obj")).exit_code, 1);
  }
  EXPECT_EQ(run("generate nosuchshape -o " + temp_path("x.ply")).exit_code, 2);
  EXPECT_EQ(run("generate demo").exit_code, 2);                           // -o is required
  EXPECT_EQ(run("generate grid -o " + temp_path("x.xyz")).exit_code, 1);  // no such format
}

}  // namespace
}  // namespace meshstream
