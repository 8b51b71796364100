// The two mesh subcommands as a user runs them: `meshstream generate` and
// `meshstream info` on a mesh file (exit codes 0 / 1 / 2, JSON fields).
// Skipped when the meshstream binary has not been built.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
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

// Issue 21 row 11: info names the attributes, materials and properties a
// file holds, also those import does not keep, in text and JSON.
TEST(MeshCommands, InfoReportsWhatTheFileHoldsEvenWhatImportDrops) {
  REQUIRE_BINARY();
  const std::string path = temp_path("per_face.obj");
  std::ofstream(path) << "mtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                         "vt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nvn 0 0 -1\n"
                         "usemtl shiny\nf 1/1/1 2/2/1 3/3/1\nf 2/1/2 4/2/2 3/3/2\n";
  const CommandResult text = run("info " + path);
  const CommandResult json_run = run("info --json " + path);
  std::filesystem::remove(path);
  ASSERT_EQ(text.exit_code, 0) << text.out;
  EXPECT_NE(text.out.find("file holds (OBJ"), std::string::npos) << text.out;
  // Per-face values are seams now: kept per corner (issue 18).
  EXPECT_NE(text.out.find("texture coordinates   3 'vt' lines (kept by import"), std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("normals               2 'vn' lines (kept by import"), std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("texcoords       per corner (3 values, 1 seam vertices)"),
            std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("material library      nowhere.mtl (not found"), std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("materials used        shiny"), std::string::npos) << text.out;
  EXPECT_EQ(text.out.find("attributes      none\n"), std::string::npos) << text.out;
  ASSERT_EQ(json_run.exit_code, 0);
  const auto json = nlohmann::json::parse(json_run.out);
  const auto& contents = json["contents"];
  EXPECT_EQ(contents["format"], "OBJ");
  EXPECT_EQ(contents["texcoords"]["count"], 3);
  EXPECT_EQ(contents["texcoords"]["kept_by_import"], true);
  EXPECT_EQ(json["attribute_forms"]["texcoords"]["per"], "corner");
  EXPECT_EQ(json["attribute_forms"]["texcoords"]["seam_vertices"], 1);
  EXPECT_EQ(json["materials"][0]["name"], "shiny");
  EXPECT_TRUE(json["warnings"].is_array());
  EXPECT_EQ(contents["normals"]["count"], 2);
  EXPECT_EQ(contents["colors"]["count"], 0);
  EXPECT_EQ(contents["material_libraries"][0]["name"], "nowhere.mtl");
  EXPECT_EQ(contents["material_libraries"][0]["found"], false);
  EXPECT_EQ(contents["materials_used"][0], "shiny");
}

TEST(MeshCommands, InfoOfKeptAttributesSaysEncodeCarriesThem) {
  REQUIRE_BINARY();
  const std::string path = temp_path("per_vertex.obj");
  std::ofstream(path) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";
  const CommandResult text = run("info " + path);
  const CommandResult json_run = run("info --json " + path);
  std::filesystem::remove(path);
  ASSERT_EQ(text.exit_code, 0);
  EXPECT_NE(text.out.find("texture coordinates   3 'vt' lines (kept by import and subdivide; "
                          "carried by encode)"),
            std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("attributes      texture coordinates (carried by encode"),
            std::string::npos)
      << text.out;
  const auto json = nlohmann::json::parse(json_run.out);
  EXPECT_EQ(json["contents"]["texcoords"]["kept_by_import"], true);
  EXPECT_EQ(json["contents"]["texcoords"]["carried_by_encode"], true);
}

TEST(MeshCommands, InfoOfTheSharedFilesNamesTheirAttributes) {
  REQUIRE_BINARY();
  MESHSTREAM_REQUIRE_TEST_MESHES();
  const CommandResult cube = run("info " + testing::test_mesh("cube_att.obj"));
  // Per-face values are kept per corner now (seams), and the stream carries them.
  EXPECT_NE(cube.out.find("normals               6 'vn' lines (kept by import and subdivide; "
                          "carried by encode)"),
            std::string::npos)
      << cube.out;
  EXPECT_NE(cube.out.find("texture coordinates   4 'vt' lines (kept by import and subdivide; "
                          "carried by encode)"),
            std::string::npos)
      << cube.out;
  const auto bunny =
      nlohmann::json::parse(run("info --json " + testing::test_mesh("bun_zipper.ply")).out);
  EXPECT_EQ(bunny["contents"]["extra_properties"],
            (nlohmann::json{"vertex confidence (float)", "vertex intensity (float)"}));
  const std::string usb = testing::test_mesh_dir() + "/../models/usb/usb.obj";
  if (!std::filesystem::exists(usb)) GTEST_SKIP() << "../shared/models/usb/usb.obj not found";
  const CommandResult text = run("info " + usb);
  EXPECT_NE(text.out.find("texture coordinates   601 'vt' lines (kept by import and subdivide; "
                          "carried by encode)"),
            std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("material library      usb.mtl: 1 material (Material_usb.jpg), "
                          "textures usb.jpg; Kd and map_Kd kept"),
            std::string::npos)
      << text.out;
  const auto json = nlohmann::json::parse(run("info --json " + usb).out);
  EXPECT_EQ(json["contents"]["texcoords"]["count"], 601);
  EXPECT_EQ(json["contents"]["material_libraries"][0]["textures"][0], "usb.jpg");
}

// `compare` against a decode whose quantization folded two one-face
// components flat: one to a segment, one to a point (vertices at one
// position, as a decoder writes them). They are still surface: the distance
// is to the segment and the point, not to the square 9 and 19 units away.
TEST(MeshCommands, CompareMeasuresFoldedFacesAsTheirSegmentOrPoint) {
  REQUIRE_BINARY();
  const std::string square = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";
  const std::string original_path = temp_path("original.obj");
  const std::string folded_path = temp_path("folded.obj");
  {
    std::ofstream original(original_path);
    original << square << "v 10 0 0\nv 10.5 0 0\nv 10 0.5 0\nf 5 6 7\n"
             << "v 20 0 0\nv 20.5 0 0\nv 20 0.5 0\nf 8 9 10\n";
    std::ofstream folded(folded_path);
    folded << square << "v 10 0 0\nv 10.5 0 0\nv 10.25 0 0\nf 5 6 7\n"
           << "v 20.25 0 0\nv 20.25 0 0\nv 20.25 0 0\nf 8 9 10\n";
  }
  const CommandResult compared = run("compare --json " + original_path + " " + folded_path);
  ASSERT_EQ(compared.exit_code, 0) << compared.out;
  const auto json = nlohmann::json::parse(compared.out);
  EXPECT_EQ(json["b"]["faces"], 4);  // the folded faces are kept
  // (10, 0.5) is 0.5 from the segment; (20, 0.5) is hypot(0.25, 0.5) from the point.
  EXPECT_NEAR(json["a_to_b"]["max"].get<double>(), std::hypot(0.25, 0.5), 1e-6);
  EXPECT_LE(json["b_to_a"]["max"].get<double>(), 1e-6);
  std::filesystem::remove(original_path);
  std::filesystem::remove(folded_path);
}

TEST(MeshCommands, BadDataExitsOneAndBadUsageTwo) {
  REQUIRE_BINARY();
  EXPECT_EQ(run("info /nonexistent/mesh.obj").exit_code, 1);
  if (!testing::test_mesh_dir().empty()) {
    EXPECT_EQ(run("info " + testing::test_mesh("inf_nan.obj")).exit_code, 1);
  }
  EXPECT_EQ(run("generate nosuchshape -o " + temp_path("x.ply")).exit_code, 2);
  EXPECT_EQ(run("generate demo").exit_code, 2);                           // -o is required
  EXPECT_EQ(run("generate grid -o " + temp_path("x.xyz")).exit_code, 2);  // no such format
}

}  // namespace
}  // namespace meshstream
