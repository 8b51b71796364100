// export -> import gives back the same mesh: positions bit-identical, the
// same triangles in the same order, attributes preserved (colours up to the
// 8-bit quantization PLY stores).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <functional>

#include "common/mesh/export.h"
#include "common/mesh/import.h"
#include "tests/test_meshes.h"

namespace meshstream {
namespace {

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("meshstream_export_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

bool same_bits(const Vec3f& a, const Vec3f& b) { return std::memcmp(&a, &b, sizeof(a)) == 0; }

// A small closed mesh with awkward coordinates: values with many digits,
// tiny and huge magnitudes, negative zero.
Mesh awkward_octahedron() {
  Mesh m;
  m.positions = {{1.0f / 3.0f, 0, 0},       {-0.1f, -0.0f, 1e-30f},
                 {0, 123456.789f, 0},       {3.4e38f, -1.17549435e-38f, 7e-8f},
                 {0.3f, 0.7f, 2.0f / 7.0f}, {-5, -6, -7.000001f}};
  m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                 {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return m;
}

struct Format {
  const char* name;
  const char* extension;
  std::function<Status(const Mesh&, const std::string&)> write;
};

const Format kFormats[] = {
    {"ply_binary", ".ply",
     [](const Mesh& m, const std::string& p) { return write_ply(m, p, PlyEncoding::kBinary); }},
    {"ply_ascii", ".ply",
     [](const Mesh& m, const std::string& p) { return write_ply(m, p, PlyEncoding::kAscii); }},
    {"obj", ".obj", [](const Mesh& m, const std::string& p) { return write_obj(m, p); }},
};

// Writes, reads back without welding (so vertex copies made by a repair stay
// apart), and checks exactness.
void expect_round_trip(const Mesh& mesh, const Format& format, const std::string& label) {
  const std::string path = temp_path(label + "_" + format.name + format.extension);
  ASSERT_TRUE(format.write(mesh, path)) << path;
  ImportOptions as_is;
  as_is.weld = false;
  auto back = import_mesh(path, as_is);
  std::filesystem::remove(path);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_FALSE(back->report.changed()) << label << " " << format.name;
  ASSERT_EQ(back->mesh.vertex_count(), mesh.vertex_count()) << label << " " << format.name;
  ASSERT_EQ(back->mesh.face_count(), mesh.face_count()) << label << " " << format.name;
  uint32_t differing = 0;
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    differing += !same_bits(mesh.positions[v], back->mesh.positions[v]);
  }
  EXPECT_EQ(differing, 0u) << label << " " << format.name << ": positions changed";
  EXPECT_TRUE(mesh.triangles == back->mesh.triangles) << label << " " << format.name;
}

TEST(ExportRoundTrip, AwkwardFloatsSurviveEveryFormat) {
  for (const Format& format : kFormats) expect_round_trip(awkward_octahedron(), format, "awkward");
}

TEST(ExportRoundTrip, AttributesSurvivePly) {
  Mesh mesh = awkward_octahedron();
  mesh.normals.resize(mesh.vertex_count());
  mesh.colors.resize(mesh.vertex_count());
  mesh.texcoords.resize(mesh.vertex_count());
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    mesh.normals[v] = normalized(Vec3f{1.0f + v, 2.0f - v, 0.5f});
    mesh.colors[v] = {v / 5.0f, 1.0f - v / 5.0f, 0.25f, 1.0f};
    mesh.texcoords[v] = {v * 0.125f, 1.0f / (v + 3.0f)};
  }
  for (PlyEncoding encoding : {PlyEncoding::kBinary, PlyEncoding::kAscii}) {
    const std::string path = temp_path("attributes.ply");
    ASSERT_TRUE(write_ply(mesh, path, encoding));
    ImportOptions as_is;
    as_is.weld = false;
    auto back = import_mesh(path, as_is);
    std::filesystem::remove(path);
    ASSERT_TRUE(back) << back.error().message;
    ASSERT_EQ(back->mesh.normals.size(), mesh.normals.size());
    for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
      EXPECT_TRUE(same_bits(back->mesh.normals[v], mesh.normals[v])) << v;
    }
    ASSERT_EQ(back->mesh.colors.size(), mesh.colors.size());
    for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
      EXPECT_NEAR(back->mesh.colors[v].x, mesh.colors[v].x, 0.5 / 255 + 1e-6);
      EXPECT_NEAR(back->mesh.colors[v].y, mesh.colors[v].y, 0.5 / 255 + 1e-6);
      EXPECT_NEAR(back->mesh.colors[v].w, 1.0, 1e-6);
    }
    ASSERT_EQ(back->mesh.texcoords.size(), mesh.texcoords.size());
    for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
      EXPECT_EQ(back->mesh.texcoords[v].x, mesh.texcoords[v].x);
      EXPECT_EQ(back->mesh.texcoords[v].y, mesh.texcoords[v].y);
    }
  }
}

TEST(ExportRoundTrip, AttributesSurviveObj) {
  Mesh mesh = awkward_octahedron();
  mesh.normals.resize(mesh.vertex_count());
  mesh.texcoords.resize(mesh.vertex_count());
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    mesh.normals[v] = normalized(Vec3f{1.0f + v, 2.0f - v, 0.5f});
    mesh.texcoords[v] = {v * 0.125f, 1.0f / (v + 3.0f)};
  }
  const std::string path = temp_path("attributes.obj");
  ASSERT_TRUE(write_obj(mesh, path));
  ImportOptions as_is;
  as_is.weld = false;
  auto back = import_mesh(path, as_is);
  std::filesystem::remove(path);
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_EQ(back->mesh.normals.size(), mesh.normals.size());
  ASSERT_EQ(back->mesh.texcoords.size(), mesh.texcoords.size());
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    EXPECT_TRUE(same_bits(back->mesh.normals[v], mesh.normals[v])) << v;
    EXPECT_EQ(back->mesh.texcoords[v].x, mesh.texcoords[v].x);
    EXPECT_EQ(back->mesh.texcoords[v].y, mesh.texcoords[v].y);
  }
}

// Real meshes, repaired ones included (their vertex copies must stay apart).
TEST(ExportRoundTrip, RealMeshesAreExact) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  for (const char* name : {"bunny.off", "dragon_res3.ply", "suzanne.obj", "maneki-neko.off"}) {
    auto imported = import_mesh(testing::test_mesh(name));
    ASSERT_TRUE(imported) << imported.error().message;
    for (const Format& format : kFormats) expect_round_trip(imported->mesh, format, name);
  }
}

TEST(Export, RefusesInvalidMeshesAndUnknownExtensions) {
  Mesh bad = awkward_octahedron();
  bad.triangles[0][0] = 99;
  EXPECT_FALSE(write_ply(bad, temp_path("bad.ply")));
  EXPECT_FALSE(write_mesh(awkward_octahedron(), temp_path("mesh.stl")));
  EXPECT_EQ(write_mesh(awkward_octahedron(), "/nonexistent/dir/x.ply").error().code,
            ErrorCode::kIo);
}

}  // namespace
}  // namespace meshstream
