// Broken and awkward input: a clear error naming the file and the problem,
// or a visible repair — never a crash.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/mesh/adjacency.h"
#include "common/mesh/import.h"
#include "common/mesh/topology.h"
#include "tests/mesh/temp_file.h"
#include "tests/test_meshes.h"

namespace meshstream {
namespace {

using ::testing::HasSubstr;

using testing::TempFile;

TEST(ImportErrors, NanAndInfAreRefusedNamingFileAndVertex) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  auto imported = import_mesh(testing::test_mesh("inf_nan.obj"));
  ASSERT_FALSE(imported);
  EXPECT_EQ(imported.error().code, ErrorCode::kInvalidMesh);
  EXPECT_THAT(imported.error().message, HasSubstr("inf_nan.obj"));
  EXPECT_THAT(imported.error().message, HasSubstr("vertex 0"));
  EXPECT_THAT(imported.error().message, HasSubstr("NaN/Inf"));
}

TEST(ImportErrors, OnlyDegenerateFacesMeansNoUsableTriangle) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  auto imported = import_mesh(testing::test_mesh("degenerate_mesh.obj"));
  ASSERT_FALSE(imported);
  EXPECT_EQ(imported.error().code, ErrorCode::kInvalidMesh);
  EXPECT_THAT(imported.error().message, HasSubstr("degenerate_mesh.obj"));
  EXPECT_THAT(imported.error().message, HasSubstr("no usable triangle"));
}

TEST(ImportErrors, DegenerateFaceIsDroppedAndReported) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  auto imported = import_mesh(testing::test_mesh("deg_faces.obj"));
  ASSERT_TRUE(imported) << imported.error().message;
  EXPECT_EQ(imported->report.degenerate_faces, 1u);
  EXPECT_EQ(imported->report.unreferenced_vertices, 1u);
  EXPECT_TRUE(imported->report.changed());
  EXPECT_EQ(imported->mesh.face_count(), 3u);
  EXPECT_EQ(imported->mesh.vertex_count(), 5u);
}

// For distances (`meshstream compare`): a face that repeats a vertex is kept
// as the segment or point it is, and counted; without analysis mode the
// option does nothing (repair needs real triangles).
TEST(ImportErrors, DegenerateFaceIsKeptForDistancesWhenAsked) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  ImportOptions distances;
  distances.keep_nonmanifold = true;
  distances.keep_degenerate_faces = true;
  distances.drop_duplicate_faces = false;
  auto kept = import_mesh(testing::test_mesh("deg_faces.obj"), distances);
  ASSERT_TRUE(kept) << kept.error().message;
  EXPECT_EQ(kept->report.degenerate_faces, 1u);
  EXPECT_EQ(kept->report.unreferenced_vertices, 1u);  // vertex 5 is in no face at all
  EXPECT_EQ(kept->mesh.face_count(), 4u);
  EXPECT_EQ(kept->mesh.vertex_count(), 5u);

  ImportOptions repairing;
  repairing.keep_degenerate_faces = true;
  auto dropped = import_mesh(testing::test_mesh("deg_faces.obj"), repairing);
  ASSERT_TRUE(dropped) << dropped.error().message;
  EXPECT_EQ(dropped->mesh.face_count(), 3u);
}

TEST(ImportErrors, NonManifoldEdgeIsRefusedWhenRepairIsOff) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  ImportOptions strict;
  strict.repair_nonmanifold = false;
  auto imported = import_mesh(testing::test_mesh("non_manifold_wrap.obj"), strict);
  ASSERT_FALSE(imported);
  EXPECT_EQ(imported.error().code, ErrorCode::kNonManifold);
  EXPECT_THAT(imported.error().message, HasSubstr("non_manifold_wrap.obj"));
  EXPECT_THAT(imported.error().message, HasSubstr("non-manifold edge"));
  EXPECT_THAT(imported.error().message, HasSubstr("4 faces"));
}

TEST(ImportErrors, NonManifoldEdgeIsRepairedByDefault) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  auto imported = import_mesh(testing::test_mesh("non_manifold_wrap.obj"));
  ASSERT_TRUE(imported) << imported.error().message;
  EXPECT_EQ(imported->report.nonmanifold_edges, 1u);
  EXPECT_GT(imported->report.split_vertices, 0u);
  EXPECT_EQ(imported->mesh.face_count(), 12u);
  EXPECT_TRUE(Adjacency::build(imported->mesh));
}

TEST(ImportErrors, NonManifoldVertexIsRefusedWhenRepairIsOff) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  ImportOptions strict;
  strict.repair_nonmanifold = false;
  auto imported = import_mesh(testing::test_mesh("test_nm.obj"), strict);
  ASSERT_FALSE(imported);
  EXPECT_EQ(imported.error().code, ErrorCode::kNonManifold);
  EXPECT_THAT(imported.error().message, HasSubstr("non-manifold vertex"));
}

TEST(ImportErrors, MissingFileIsAnIoError) {
  auto imported = import_mesh("/nonexistent/dir/missing.obj");
  ASSERT_FALSE(imported);
  EXPECT_EQ(imported.error().code, ErrorCode::kIo);
  EXPECT_THAT(imported.error().message, HasSubstr("missing.obj"));
}

TEST(ImportErrors, DirectoryIsNotAMesh) {
  auto imported = import_mesh(std::filesystem::temp_directory_path().string());
  ASSERT_FALSE(imported);
}

TEST(ImportErrors, UnknownExtensionIsAParseError) {
  TempFile file("mesh.xyz", "1 2 3\n");
  auto imported = import_mesh(file.path());
  ASSERT_FALSE(imported);
  EXPECT_EQ(imported.error().code, ErrorCode::kParse);
  EXPECT_THAT(imported.error().message, HasSubstr(".xyz"));
}

TEST(ImportErrors, EmptyFileIsRefused) {
  for (const char* name : {"empty.obj", "empty.off", "empty.ply", "empty.stl"}) {
    TempFile file(name, "");
    auto imported = import_mesh(file.path());
    ASSERT_FALSE(imported) << name;
    EXPECT_THAT(imported.error().message, HasSubstr(name));
  }
}

TEST(ImportErrors, ObjIndexOutOfRangeIsRefused) {
  TempFile file("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  auto imported = import_mesh(file.path());
  ASSERT_FALSE(imported);
  EXPECT_THAT(imported.error().message, HasSubstr("range.obj"));
}

TEST(ImportErrors, ObjWithoutFacesHasNoUsableTriangle) {
  TempFile file("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  auto imported = import_mesh(file.path());
  ASSERT_FALSE(imported);
  EXPECT_EQ(imported.error().code, ErrorCode::kInvalidMesh);
  EXPECT_THAT(imported.error().message, HasSubstr("no usable triangle"));
}

TEST(ImportErrors, MoebiusStripIsRefusedAsNonOrientable) {
  // A strip of 6 quads whose ends are glued with a half twist.
  std::string obj;
  const int n = 6;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * 3.14159265358979 * i / n;
    obj += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0.3\n";
    obj += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " -0.3\n";
  }
  for (int i = 0; i < n; ++i) {
    const int top = 2 * i + 1, bottom = 2 * i + 2;
    int next_top = 2 * ((i + 1) % n) + 1, next_bottom = 2 * ((i + 1) % n) + 2;
    if (i == n - 1) std::swap(next_top, next_bottom);  // the half twist
    obj += "f " + std::to_string(top) + " " + std::to_string(bottom) + " " +
           std::to_string(next_bottom) + "\n";
    obj += "f " + std::to_string(top) + " " + std::to_string(next_bottom) + " " +
           std::to_string(next_top) + "\n";
  }
  TempFile file("moebius.obj", obj);
  auto imported = import_mesh(file.path());
  ASSERT_FALSE(imported);
  EXPECT_EQ(imported.error().code, ErrorCode::kNonManifold);
  EXPECT_THAT(imported.error().message, HasSubstr("oriented"));
}

TEST(ImportErrors, StlWithAnInconsistentFaceIsFlipped) {
  // A tetrahedron whose last face is wound the wrong way.
  TempFile file("flip.obj",
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n");
  auto good = import_mesh(file.path());
  ASSERT_TRUE(good) << good.error().message;
  EXPECT_EQ(good->report.flipped_faces, 0u);
  TempFile bad("flip_bad.obj",
               "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
               "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 4 1\n");
  ImportOptions strict;
  strict.repair_nonmanifold = false;
  auto refused = import_mesh(bad.path(), strict);
  ASSERT_FALSE(refused);
  EXPECT_THAT(refused.error().message, HasSubstr("same direction"));
  auto repaired = import_mesh(bad.path());
  ASSERT_TRUE(repaired) << repaired.error().message;
  EXPECT_EQ(repaired->report.flipped_faces, 1u);
  EXPECT_TRUE(Adjacency::build(repaired->mesh));
}

TEST(ImportErrors, BowtieVertexIsSplit) {
  // Two triangles touching at one vertex: one vertex, two fans.
  TempFile file("bowtie.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv -1 0 0\nv -1 -1 0\nf 1 2 3\nf 1 4 5\n");
  auto imported = import_mesh(file.path());
  ASSERT_TRUE(imported) << imported.error().message;
  EXPECT_EQ(imported->report.nonmanifold_vertices, 1u);
  EXPECT_EQ(imported->report.split_vertices, 1u);
  EXPECT_EQ(imported->mesh.vertex_count(), 6u);
  EXPECT_TRUE(Adjacency::build(imported->mesh));
}

TEST(ImportErrors, ThreeSheetsOnOneEdgeAreDetached) {
  // Three triangles on edge (1,2): the third cannot stay.
  TempFile file("fin.obj",
                "v 0 0 0\nv 1 0 0\nv 0.5 1 0\nv 0.5 -1 0\nv 0.5 0 1\n"
                "f 1 2 3\nf 2 1 4\nf 1 2 5\n");
  auto imported = import_mesh(file.path());
  ASSERT_TRUE(imported) << imported.error().message;
  EXPECT_EQ(imported->report.nonmanifold_edges, 1u);
  EXPECT_EQ(imported->mesh.face_count(), 3u);
  EXPECT_TRUE(Adjacency::build(imported->mesh));
}

TEST(ImportErrors, TwoSheetsCrossingAlongAnEdgeSeparateCleanly) {
  // Two flat sheets (one in z = 0, one in y = 0) share the edge (1, 2): four
  // faces there. The repair pairs each sheet's faces and splits the edge's
  // vertices instead of cutting faces off.
  TempFile file("cross.obj",
                "v 0 0 0\nv 1 0 0\nv 0.5 1 0\nv 0.5 -1 0\nv 0.5 0 1\nv 0.5 0 -1\n"
                "f 1 2 3\nf 2 1 4\nf 1 2 5\nf 2 1 6\n");
  auto imported = import_mesh(file.path());
  ASSERT_TRUE(imported) << imported.error().message;
  EXPECT_EQ(imported->report.nonmanifold_edges, 1u);
  EXPECT_EQ(imported->report.detached_faces, 0u);
  EXPECT_EQ(imported->report.split_vertices, 2u);
  const MeshStats stats = compute_stats(imported->mesh);
  EXPECT_EQ(stats.components, 2u);
  EXPECT_EQ(stats.boundary_edges, 8u);
  EXPECT_TRUE(Adjacency::build(imported->mesh));
}

TEST(ImportErrors, WrapIsSplitIntoItsTwoSheets) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  auto imported = import_mesh(testing::test_mesh("non_manifold_wrap.obj"));
  ASSERT_TRUE(imported) << imported.error().message;
  EXPECT_EQ(imported->report.detached_faces, 0u);
  const MeshStats stats = compute_stats(imported->mesh);
  EXPECT_EQ(stats.components, 2u);
  EXPECT_EQ(stats.boundary_edges, 8u);  // as in the file: no new cut
}

TEST(ImportErrors, DoubleSidedFlapIsDroppedNotKeptAsAPiece) {
  // A closed tetrahedron plus a double-sided triangle (a face and its
  // reverse) hanging off its edge (1, 2): the duplicate goes, the remaining
  // copy is cut loose by the repair and then dropped as a flap.
  const std::string tetra =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\n"
      "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
  TempFile file("flap.obj", tetra + "f 1 2 5\nf 2 1 5\n");
  auto imported = import_mesh(file.path());
  ASSERT_TRUE(imported) << imported.error().message;
  EXPECT_EQ(imported->report.duplicate_faces, 1u);
  EXPECT_EQ(imported->report.double_sided_flaps, 1u);
  EXPECT_EQ(imported->mesh.face_count(), 4u);
  EXPECT_EQ(imported->mesh.vertex_count(), 4u);
  const MeshStats stats = compute_stats(imported->mesh);
  EXPECT_EQ(stats.components, 1u);
  EXPECT_EQ(stats.boundary_edges, 0u);
  // With the option off the flap stays, as its own component.
  ImportOptions keep;
  keep.drop_double_sided_flaps = false;
  auto kept = import_mesh(file.path(), keep);
  ASSERT_TRUE(kept) << kept.error().message;
  EXPECT_EQ(kept->mesh.face_count(), 5u);
  EXPECT_EQ(compute_stats(kept->mesh).components, 2u);
  EXPECT_TRUE(Adjacency::build(kept->mesh));
}

}  // namespace
}  // namespace meshstream
