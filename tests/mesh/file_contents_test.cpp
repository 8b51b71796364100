// What a file holds, kept by import or not (ImportedMesh::contents, the
// "file holds" part of `meshstream info`): attribute counts and why they
// were dropped, OBJ materials, PLY properties and elements the reader skips,
// OFF face colours. Inline files, procedural meshes written out, and the
// real files of ../shared (skipped visibly when absent).
#include "common/mesh/file_contents.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "common/mesh/export.h"
#include "common/mesh/import.h"
#include "common/mesh/procedural.h"
#include "tests/mesh/temp_file.h"
#include "tests/test_meshes.h"

namespace meshstream {
namespace {

using testing::TempFile;

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

ImportedMesh import_ok(const std::string& path) {
  auto imported = import_mesh(path);
  EXPECT_TRUE(imported) << path << ": " << imported.error().message;
  return imported ? std::move(*imported) : ImportedMesh{};
}

// A unit square of two triangles, its corners with per-face normals (two
// 'vn' values at a shared vertex disagree) and consistent texture
// coordinates, two materials from a library beside the file.
TEST(FileContents, ObjCountsAttributesAndNamesMaterials) {
  TempFile mtl("square.mtl",
               "newmtl red\nKd 1 0 0\nmap_Kd -bm 1 red.png\nnewmtl blue\nmap_Kd blue.jpg\n"
               "map_Bump blue.jpg\n");
  const std::string library = std::filesystem::path(mtl.path()).filename().string();
  TempFile obj("square.obj", "mtllib " + library +
                                 "\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                 "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                 "vn 0 0 1\nvn 0 0.6 0.8\nvn 0 0.8 0.6\n"
                                 "usemtl red\nf 1/1/1 2/2/1 3/3/1\n"
                                 "usemtl blue\nf 1/1/2 3/3/3 4/4/3\nusemtl red\n");
  const ImportedMesh m = import_ok(obj.path());
  const FileContents& c = m.contents;
  EXPECT_EQ(c.format, "OBJ");
  EXPECT_EQ(c.texcoords.count, 4u);
  EXPECT_TRUE(c.texcoords.dropped.empty());
  EXPECT_EQ(m.mesh.texcoords.size(), 4u);  // consistent per vertex: kept
  EXPECT_EQ(c.normals.count, 3u);
  EXPECT_TRUE(c.normals.dropped.empty()) << c.normals.dropped;
  EXPECT_TRUE(m.mesh.normals.empty());  // a seam at vertices 1 and 3: per corner
  EXPECT_EQ(m.mesh.corner_normals.values.size(), 3u);
  EXPECT_EQ(m.mesh.corner_normals.corners.size(), 6u);
  // usemtl groups: face 0 red, face 1 blue, Kd from the library; the
  // textures' files are absent, so named in notes.
  ASSERT_EQ(m.mesh.materials.size(), 2u);
  EXPECT_EQ(m.mesh.face_materials, (std::vector<uint32_t>{0, 1}));
  EXPECT_EQ(m.mesh.materials[0].base_color.x, 1.0f);
  EXPECT_EQ(m.mesh.materials[0].base_color.y, 0.0f);
  EXPECT_EQ(m.mesh.materials[0].base_color_texture, -1);
  bool named = false;
  for (const std::string& note : m.report.notes) named |= note.find("red.png") != std::string::npos;
  EXPECT_TRUE(named) << "the missing texture file is named in a note";
  EXPECT_EQ(c.colors.count, 0u);
  ASSERT_EQ(c.material_libraries.size(), 1u);
  EXPECT_EQ(c.material_libraries[0].name, library);
  EXPECT_EQ(c.materials_used, (std::vector<std::string>{"red", "blue"}));

  const MaterialLibrary read = read_material_library(obj.path(), library);
  EXPECT_TRUE(read.found);
  EXPECT_EQ(read.materials, (std::vector<std::string>{"red", "blue"}));
  EXPECT_EQ(read.textures, (std::vector<std::string>{"red.png", "blue.jpg"}));
  EXPECT_FALSE(read_material_library(obj.path(), "absent.mtl").found);
}

TEST(FileContents, ObjVertexColoursOnSomeVerticesAreCountedAndDropped) {
  TempFile obj("some_colours.obj", "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const ImportedMesh m = import_ok(obj.path());
  EXPECT_EQ(m.contents.colors.count, 1u);
  EXPECT_NE(m.contents.colors.dropped.find("only 1 of 3"), std::string::npos);
  EXPECT_TRUE(m.mesh.colors.empty());
}

TEST(FileContents, PlyListsThePropertiesAndElementsItSkips) {
  TempFile ply("extras.ply",
               "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
               "property float z\nproperty float confidence\nproperty uchar red\n"
               "property uchar green\nproperty uchar blue\n"
               "element face 1\nproperty list uchar int vertex_indices\nproperty int flags\n"
               "element edge 2\nproperty int vertex1\nproperty int vertex2\nend_header\n"
               "0 0 0 0.5 255 0 0\n1 0 0 0.5 0 255 0\n0 1 0 0.5 0 0 255\n3 0 1 2 7\n0 1\n1 2\n");
  const ImportedMesh m = import_ok(ply.path());
  const FileContents& c = m.contents;
  EXPECT_EQ(c.format, "PLY (ascii)");
  EXPECT_EQ(c.colors.count, 3u);
  EXPECT_EQ(m.mesh.colors.size(), 3u);
  EXPECT_EQ(c.normals.count, 0u);
  EXPECT_EQ(c.extra_properties,
            (std::vector<std::string>{"vertex confidence (float)", "face flags (int)"}));
  EXPECT_EQ(c.other_elements, (std::vector<std::string>{"edge (2)"}));
}

TEST(FileContents, OffCountsFaceColoursAndVertexAttributes) {
  TempFile off("coloured.off",
               "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2 255 0 0\n");
  const ImportedMesh m = import_ok(off.path());
  EXPECT_EQ(m.contents.format, "OFF");
  EXPECT_EQ(m.contents.normals.count, 3u);
  EXPECT_EQ(m.mesh.normals.size(), 3u);
  EXPECT_EQ(m.contents.extra_properties, (std::vector<std::string>{"face colour (on 1 faces)"}));
}

// A procedural mesh with texture coordinates (and colours, which only PLY
// stores), written and read back: counted and kept.
TEST(FileContents, ProceduralMeshWithAttributesRoundTrips) {
  Mesh sphere = make_icosphere(2);
  for (const Vec3f& p : sphere.positions) {
    sphere.texcoords.push_back({p.x * 0.5f + 0.5f, p.y * 0.5f + 0.5f});
    sphere.colors.push_back({p.x * 0.5f + 0.5f, 0.25f, 0.75f, 1.0f});
  }
  for (const char* name : {"sphere_attr.ply", "sphere_attr.obj"}) {
    TempFile file(name, "");
    ASSERT_TRUE(write_mesh(sphere, file.path()));
    const ImportedMesh m = import_ok(file.path());
    EXPECT_EQ(m.contents.texcoords.count, sphere.vertex_count()) << name;
    EXPECT_TRUE(m.contents.texcoords.dropped.empty()) << name;
    EXPECT_EQ(m.mesh.texcoords.size(), sphere.vertex_count()) << name;
    const bool ply = std::string(name).ends_with(".ply");
    EXPECT_EQ(m.contents.colors.count, ply ? sphere.vertex_count() : 0u) << name;
  }
}

TEST(FileContents, PlainMeshHoldsNothingElse) {
  TempFile obj("plain.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const FileContents c = import_ok(obj.path()).contents;
  EXPECT_EQ(c.normals.count + c.texcoords.count + c.colors.count, 0u);
  EXPECT_TRUE(c.material_libraries.empty());
  EXPECT_TRUE(c.extra_properties.empty());
}

// The shared files the issue names: ../shared/meshes and ../shared/models.
TEST(FileContents, RealFilesReportWhatTheyHold) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  const ImportedMesh cube = import_ok(testing::test_mesh("cube_att.obj"));
  EXPECT_EQ(cube.contents.normals.count, 6u);
  EXPECT_EQ(cube.contents.texcoords.count, 4u);
  // Per-face values are seams, kept per corner (issue 18).
  EXPECT_TRUE(cube.contents.normals.dropped.empty());
  EXPECT_TRUE(cube.contents.texcoords.dropped.empty());
  EXPECT_FALSE(cube.mesh.corner_normals.empty());

  const ImportedMesh bunny = import_ok(testing::test_mesh("bun_zipper.ply"));
  EXPECT_TRUE(contains(bunny.contents.extra_properties, "vertex confidence (float)"));
  EXPECT_TRUE(contains(bunny.contents.extra_properties, "vertex intensity (float)"));
}

TEST(FileContents, UsbModelTextureCoordinatesAndMaterial) {
  const std::string usb = testing::test_mesh_dir() + "/../models/usb/usb.obj";
  if (testing::test_mesh_dir().empty() || !std::filesystem::exists(usb))
    GTEST_SKIP() << "../shared/models/usb/usb.obj not found";
  const ImportedMesh m = import_ok(usb);
  EXPECT_EQ(m.contents.texcoords.count, 601u);
  EXPECT_TRUE(m.contents.texcoords.dropped.empty());  // kept per corner (issue 18)
  EXPECT_FALSE(m.mesh.corner_texcoords.empty());
  ASSERT_EQ(m.contents.material_libraries.size(), 1u);
  const MaterialLibrary library = read_material_library(usb, m.contents.material_libraries[0].name);
  EXPECT_TRUE(library.found);
  EXPECT_TRUE(contains(library.textures, "usb.jpg"));
}

}  // namespace
}  // namespace meshstream
