// Our binary STL reader against Draco's StlDecoder (the reader import used
// before): the same corners in the same order, the same faces; facet normals
// counted, not kept (so they do not become a seam at every vertex).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

#include "common/mesh/export.h"
#include "common/mesh/import.h"
#include "common/mesh/mesh_readers.h"
#include "common/mesh/procedural.h"
#include "tests/mesh/temp_file.h"
#include "tests/test_meshes.h"

namespace meshstream {
namespace {

void expect_same_as_draco(const std::string& path) {
  auto ours = read_stl(path);
  auto draco = read_stl_with_draco(path);
  ASSERT_TRUE(ours) << ours.error().message;
  ASSERT_TRUE(draco) << draco.error().message;
  const Mesh& a = ours->mesh;
  const Mesh& b = draco->mesh;
  ASSERT_EQ(a.vertex_count(), b.vertex_count()) << path;
  ASSERT_EQ(a.face_count(), b.face_count()) << path;
  EXPECT_EQ(std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * 12), 0)
      << path;
  EXPECT_EQ(a.triangles, b.triangles) << path;
  EXPECT_EQ(ours->vertices_in_file, draco->vertices_in_file) << path;
  EXPECT_TRUE(a.normals.empty() && a.corner_normals.empty()) << path;
  EXPECT_EQ(ours->contents.normals.count, a.face_count()) << path;
  EXPECT_THAT(ours->contents.normals.dropped, ::testing::HasSubstr("per facet"));
}

TEST(StlReader, SameCornersAndFacesAsDraco) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("meshstream_stl_reader_" + std::to_string(::getpid()) + ".stl"))
                               .string();
  // More triangles than one read chunk (8192), so chunk borders are crossed.
  ASSERT_TRUE(write_stl(make_icosphere(4), path));
  expect_same_as_draco(path);
  std::filesystem::remove(path);
}

TEST(StlReader, RealBunnySameAsDracoAndWeldsWithoutSeams) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  const std::string path = testing::test_mesh("bunny.stl");
  expect_same_as_draco(path);
  // The same surface as bun_zipper.ply: no per-corner normals left to
  // block decimation at every vertex.
  auto imported = import_mesh(path);
  ASSERT_TRUE(imported) << imported.error().message;
  EXPECT_EQ(imported->mesh.vertex_count(), 34834u);
  EXPECT_TRUE(imported->mesh.corner_normals.empty());
  EXPECT_TRUE(imported->mesh.normals.empty());
}

TEST(StlReader, WrongSizeIsRefusedWithTheCounts) {
  std::string bytes(84 + 50 + 7, '\0');
  const uint32_t count = 1;
  std::memcpy(bytes.data() + 80, &count, 4);
  testing::TempFile file("odd.stl", bytes);
  auto imported = import_mesh(file.path());
  ASSERT_FALSE(imported);
  EXPECT_EQ(imported.error().code, ErrorCode::kParse);
  EXPECT_THAT(imported.error().message,
              ::testing::HasSubstr("not a binary STL: 141 bytes, but the header announces 1 "
                                   "triangles (134 bytes)"));
}

}  // namespace
}  // namespace meshstream
