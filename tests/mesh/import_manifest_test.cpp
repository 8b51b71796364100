// Every mesh of ../shared/meshes imports with the counts its MANIFEST.md
// gives (computed there by an independent tool), and the repaired result is
// a mesh the corner table accepts.
#include <gtest/gtest.h>

#include <ostream>

#include "common/mesh/adjacency.h"
#include "common/mesh/import.h"
#include "common/mesh/topology.h"
#include "tests/test_meshes.h"

namespace meshstream {
namespace {

struct ManifestRow {
  const char* file;
  uint32_t vertices;  // welded
  uint32_t in_file;
  uint32_t faces;  // after dropping degenerate faces, duplicates included
  uint32_t duplicates;
  uint32_t degenerate;
  uint32_t boundary_edges;
  uint32_t loops;
  uint32_t nm_edges;
  uint32_t nm_vertices;
  uint32_t components;
  bool manifold;
  int genus;  // -1: not given (non-manifold)
};

// Transcribed from ../shared/meshes/MANIFEST.md.
const ManifestRow kManifest[] = {
    {"bun_zipper.ply", 34834, 35947, 69451, 0, 0, 223, 5, 0, 0, 1, true, 0},
    {"bunny.off", 34835, 34835, 69666, 0, 0, 0, 0, 0, 0, 1, true, 0},
    {"bunny.stl", 34834, 208353, 69451, 0, 0, 223, 5, 0, 0, 1, true, 0},
    {"armadillo.obj", 49990, 49990, 99976, 0, 0, 0, 0, 0, 0, 1, true, 0},
    {"fandisk.off", 6475, 6475, 12946, 0, 0, 0, 0, 0, 0, 1, true, 0},
    {"crank.off", 49986, 49986, 100028, 12, 0, 0, 0, 24, 0, 1, false, -1},
    {"casting.off", 5096, 5096, 10224, 0, 0, 0, 0, 0, 0, 1, true, 9},
    {"mask.off", 31756, 31756, 62460, 0, 0, 1050, 1, 0, 0, 1, true, 0},
    {"hemisphere.off", 1861, 1861, 3600, 0, 0, 120, 1, 0, 0, 1, true, 0},
    {"skull.obj", 40062, 40062, 80016, 0, 0, 0, 0, 0, 0, 30, true, 3},
    {"maneki-neko.off", 62385, 62385, 124677, 4, 0, 67, 2, 0, 7, 7, false, -1},
    {"dragon_res2.ply", 100207, 100250, 202520, 1489, 0, 0, 0, 2534, 16, 7, false, -1},
    {"dragon_res3.ply", 22982, 22998, 47794, 1254, 0, 0, 0, 2094, 5, 1, false, -1},
    {"sphere.obj", 114, 114, 224, 0, 0, 0, 0, 0, 0, 1, true, 0},
    {"sphere_low.off", 589, 589, 1174, 0, 0, 0, 0, 0, 0, 1, true, 0},
    {"chamfer-cube.off", 24, 24, 44, 0, 0, 0, 0, 0, 0, 1, true, 0},
    {"cube_att.obj", 8, 8, 12, 0, 0, 0, 0, 0, 0, 1, true, 0},
    {"cube_quads.obj", 8, 8, 12, 0, 0, 0, 0, 0, 0, 1, true, 0},
    {"octagon.obj", 8, 8, 6, 0, 0, 8, 1, 0, 0, 1, true, 0},
    {"multiple_isolated_triangles.obj", 15, 15, 5, 0, 0, 15, 5, 0, 0, 5, true, 0},
    {"multiple_tetrahedrons.obj", 20, 20, 20, 0, 0, 0, 0, 0, 0, 5, true, 0},
    {"suzanne.obj", 505, 507, 968, 0, 0, 42, 4, 0, 2, 1, false, -1},
    {"test_nm.obj", 97, 114, 170, 0, 0, 30, 3, 0, 2, 1, false, -1},
    {"non_manifold_wrap.obj", 10, 10, 12, 0, 0, 8, 2, 1, 0, 1, false, -1},
    {"deg_faces.obj", 5, 6, 3, 0, 1, 5, 1, 0, 0, 1, true, 0},
    {"extra_vertex.obj", 9, 10, 3, 0, 0, 9, 3, 0, 0, 3, true, 0},
    {"eof_test.obj", 3, 3, 1, 0, 0, 3, 1, 0, 0, 1, true, 0},
};

// So failures name the file instead of dumping the struct's bytes.
void PrintTo(const ManifestRow& row, std::ostream* os) { *os << row.file; }

class ManifestTest : public ::testing::TestWithParam<ManifestRow> {};

// The file as the manifest describes it: welded, degenerate and unreferenced
// parts dropped, duplicates and non-manifold parts kept.
TEST_P(ManifestTest, AnalysisImportMatchesManifestCounts) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  const ManifestRow& row = GetParam();
  ImportOptions analysis;
  analysis.drop_duplicate_faces = false;
  analysis.keep_nonmanifold = true;
  auto imported = import_mesh(testing::test_mesh(row.file), analysis);
  ASSERT_TRUE(imported) << imported.error().message;
  const CleanReport& report = imported->report;
  EXPECT_EQ(report.vertices_in_file, row.in_file);
  EXPECT_EQ(imported->mesh.vertex_count(), row.vertices);
  EXPECT_EQ(imported->mesh.face_count(), row.faces);
  EXPECT_EQ(report.degenerate_faces, row.degenerate);
  EXPECT_EQ(report.faces_in_file - report.degenerate_faces, row.faces);
  EXPECT_EQ(report.vertices_in_file - report.welded_vertices - report.unreferenced_vertices,
            row.vertices);
  EXPECT_EQ(report.nonmanifold_edges, row.nm_edges);
  EXPECT_EQ(report.nonmanifold_vertices, row.nm_vertices);

  const MeshStats stats = compute_stats(imported->mesh);
  EXPECT_EQ(stats.referenced_vertices, row.vertices);
  EXPECT_EQ(stats.duplicate_faces, row.duplicates);
  EXPECT_EQ(stats.boundary_edges, row.boundary_edges);
  EXPECT_EQ(stats.boundary_loops, row.loops);
  EXPECT_EQ(stats.nonmanifold_edges, row.nm_edges);
  EXPECT_EQ(stats.nonmanifold_vertices, row.nm_vertices);
  EXPECT_EQ(stats.components, row.components);
  EXPECT_EQ(stats.manifold, row.manifold);
  // "Every mesh here is consistently oriented."
  EXPECT_EQ(stats.orientation_conflicts, 0u);
  if (row.genus >= 0) {
    ASSERT_TRUE(stats.genus_valid);
    EXPECT_EQ(stats.genus, row.genus);
  }
}

// The default import: duplicates dropped (and counted), non-manifold parts
// repaired, and the corner table builds.
TEST_P(ManifestTest, DefaultImportIsManifoldAndCountsWhatItChanged) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  const ManifestRow& row = GetParam();
  auto imported = import_mesh(testing::test_mesh(row.file));
  ASSERT_TRUE(imported) << imported.error().message;
  const CleanReport& report = imported->report;
  EXPECT_EQ(report.duplicate_faces, row.duplicates);
  EXPECT_EQ(report.degenerate_faces, row.degenerate);
  // Repair keeps every face except flaps left by double-sided triangles,
  // which only files with duplicates have.
  EXPECT_LE(report.double_sided_flaps, row.duplicates);
  EXPECT_EQ(report.faces_in_file - report.degenerate_faces - report.duplicate_faces -
                report.double_sided_flaps,
            imported->mesh.face_count());
  EXPECT_EQ(imported->mesh.face_count(), row.faces - row.duplicates - report.double_sided_flaps);
  EXPECT_EQ(report.vertices_in_file - report.welded_vertices - report.unreferenced_vertices +
                report.split_vertices,
            imported->mesh.vertex_count());
  if (report.double_sided_flaps == 0) {
    EXPECT_EQ(imported->mesh.vertex_count(), row.vertices + report.split_vertices);
  }
  // The files are consistently oriented; only dropping one of two opposite
  // duplicates can leave a face to flip.
  EXPECT_LE(report.flipped_faces, row.duplicates);
  if (row.manifold && row.duplicates == 0) {
    EXPECT_EQ(report.split_vertices, 0u);
    EXPECT_EQ(report.detached_faces, 0u);
  } else {
    EXPECT_GT(report.split_vertices + report.double_sided_flaps, 0u);  // the repair did something
  }
  EXPECT_TRUE(validate_arrays(imported->mesh));
  auto adjacency = Adjacency::build(imported->mesh);
  ASSERT_TRUE(adjacency) << adjacency.error().message;
  const MeshStats stats = compute_stats(imported->mesh);
  EXPECT_TRUE(stats.manifold);
  EXPECT_EQ(stats.orientation_conflicts, 0u);
  EXPECT_EQ(stats.duplicate_faces, 0u);
  EXPECT_EQ(stats.isolated_vertices, 0u);
  EXPECT_EQ(adjacency->edge_count(), stats.edges);
  EXPECT_EQ(adjacency->boundary_edge_count(), stats.boundary_edges);
}

INSTANTIATE_TEST_SUITE_P(Meshes, ManifestTest, ::testing::ValuesIn(kManifest),
                         [](const ::testing::TestParamInfo<ManifestRow>& info) {
                           std::string name = info.param.file;
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

}  // namespace
}  // namespace meshstream
