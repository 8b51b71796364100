// export -> import gives back the same mesh: positions bit-identical, the
// same triangles in the same order, attributes preserved (colours up to the
// 8-bit quantization PLY stores). Binary STL, positions only, comes back with
// every face's corners bit-identical after the importer welds them.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <set>
#include <string_view>

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
    {"off", ".off", [](const Mesh& m, const std::string& p) { return write_off(m, p); }},
    {"by_extension_off", ".OFF",
     [](const Mesh& m, const std::string& p) { return write_mesh(m, p); }},
};

// Writes, reads back without welding (so vertex copies made by a repair stay
// apart), and checks exactness.
void expect_round_trip(const Mesh& mesh, const Format& format, const std::string& label) {
  const std::string path = temp_path(label + "_" + format.name + format.extension);
  ASSERT_TRUE(format.write(mesh, path)) << path;
  ImportOptions as_is;
  as_is.weld = false;
  // PLY and OFF hold attributes per vertex: a seam (per-corner values) is
  // written as vertex copies, which welding joins again into the same mesh.
  const bool seams_split = std::string_view(format.extension) != ".obj" &&
                           (!mesh.corner_normals.empty() || !mesh.corner_texcoords.empty() ||
                            !mesh.corner_colors.empty());
  if (seams_split) as_is.weld = true;
  auto back = import_mesh(path, as_is);
  std::filesystem::remove(path);
  ASSERT_TRUE(back) << back.error().message;
  if (seams_split) {
    EXPECT_EQ(back->mesh.vertex_count(), mesh.vertex_count()) << label << " " << format.name;
    EXPECT_EQ(back->mesh.face_count(), mesh.face_count()) << label << " " << format.name;
    return;
  }
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

TEST(ExportRoundTrip, AttributesSurviveOff) {
  Mesh mesh = awkward_octahedron();
  mesh.normals.resize(mesh.vertex_count());
  mesh.colors.resize(mesh.vertex_count());
  mesh.texcoords.resize(mesh.vertex_count());
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    mesh.normals[v] = normalized(Vec3f{1.0f + v, 2.0f - v, 0.5f});
    mesh.colors[v] = {v / 5.0f, 1.0f - v / 5.0f, 0.25f, v == 2 ? 0.5f : 1.0f};
    mesh.texcoords[v] = {v * 0.125f, 1.0f / (v + 3.0f)};
  }
  const std::string path = temp_path("attributes.off");
  ASSERT_TRUE(write_off(mesh, path));
  ImportOptions as_is;
  as_is.weld = false;
  auto back = import_mesh(path, as_is);
  std::filesystem::remove(path);
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_EQ(back->mesh.normals.size(), mesh.normals.size());
  ASSERT_EQ(back->mesh.colors.size(), mesh.colors.size());
  ASSERT_EQ(back->mesh.texcoords.size(), mesh.texcoords.size());
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    EXPECT_TRUE(same_bits(back->mesh.normals[v], mesh.normals[v])) << v;
    // OFF colours are written as floats in 0..1, so they come back exactly.
    EXPECT_EQ(back->mesh.colors[v].x, mesh.colors[v].x) << v;
    EXPECT_EQ(back->mesh.colors[v].y, mesh.colors[v].y) << v;
    EXPECT_EQ(back->mesh.colors[v].z, mesh.colors[v].z) << v;
    EXPECT_EQ(back->mesh.colors[v].w, mesh.colors[v].w) << v;
    EXPECT_EQ(back->mesh.texcoords[v].x, mesh.texcoords[v].x) << v;
    EXPECT_EQ(back->mesh.texcoords[v].y, mesh.texcoords[v].y) << v;
  }
}

// Binary STL stores three corners per triangle, so the importer welds them
// back (bit-identical positions): for a mesh without two vertices at one
// position the result has the same vertex count and every face has the same
// corners, bit for bit, in the same order. (A mesh with such vertices, e.g.
// suzanne's seams or the dragon's repair copies, comes back with them
// welded, and import then repairs what the weld made non-manifold: STL has
// no connectivity to keep them apart.)
// Vertex numbering follows first use in the file, so faces are compared by
// their corners' positions.
size_t distinct_positions(const Mesh& mesh) {
  std::set<std::array<uint32_t, 3>> seen;
  for (const Vec3f& p : mesh.positions) {
    std::array<uint32_t, 3> bits;
    std::memcpy(bits.data(), &p, sizeof p);
    seen.insert(bits);
  }
  return seen.size();
}

void expect_stl_round_trip(const Mesh& mesh, const std::string& label, const char* extension) {
  const std::string path = temp_path(label + extension);
  ASSERT_TRUE(write_mesh(mesh, path)) << path;
  EXPECT_EQ(std::filesystem::file_size(path), 84u + 50u * mesh.face_count()) << label;
  auto back = import_mesh(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(back) << label << ": " << back.error().message;
  ASSERT_EQ(back->mesh.vertex_count(), distinct_positions(mesh)) << label;
  ASSERT_EQ(back->mesh.face_count(), mesh.face_count()) << label;
  uint32_t differing = 0;
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      differing += !same_bits(mesh.positions[mesh.triangles[f][k]],
                              back->mesh.positions[back->mesh.triangles[f][k]]);
    }
  }
  EXPECT_EQ(differing, 0u) << label << ": corners changed";
}

TEST(ExportRoundTrip, BinaryStlKeepsEveryCornerExactly) {
  expect_stl_round_trip(awkward_octahedron(), "awkward", ".stl");
  expect_stl_round_trip(awkward_octahedron(), "awkward_upper", ".STL");
}

TEST(ExportRoundTrip, BinaryStlOfRealMeshes) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  for (const char* name : {"bunny.off", "fandisk.off", "casting.off", "armadillo.obj"}) {
    auto imported = import_mesh(testing::test_mesh(name));
    ASSERT_TRUE(imported) << imported.error().message;
    // No two vertices at one position: STL gives back the same vertex count.
    ASSERT_EQ(distinct_positions(imported->mesh), imported->mesh.vertex_count()) << name;
    expect_stl_round_trip(imported->mesh, name, ".stl");
  }
}

TEST(Export, StlHeaderIsNotMistakenForAscii) {
  const std::string path = temp_path("header.stl");
  ASSERT_TRUE(write_stl(awkward_octahedron(), path));
  std::FILE* f = std::fopen(path.c_str(), "rb");
  ASSERT_NE(f, nullptr);
  char head[84];
  ASSERT_EQ(std::fread(head, 1, sizeof head, f), sizeof head);
  std::fclose(f);
  std::filesystem::remove(path);
  EXPECT_NE(std::string(head, 5), "solid");  // "solid" marks ASCII STL
  uint32_t count = 0;
  std::memcpy(&count, head + 80, 4);
  EXPECT_EQ(count, 8u);
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
  auto unknown = write_mesh(awkward_octahedron(), temp_path("mesh.xyz"));
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(unknown.error().message.find(".ply, .obj, .off, .stl, .glb or .gltf"),
            std::string::npos);
  EXPECT_FALSE(write_stl(bad, temp_path("bad.stl")));
  EXPECT_FALSE(write_off(bad, temp_path("bad.off")));
  EXPECT_EQ(write_mesh(awkward_octahedron(), "/nonexistent/dir/x.ply").error().code,
            ErrorCode::kIo);
}

}  // namespace
}  // namespace meshstream
