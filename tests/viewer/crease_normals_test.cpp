// Shading normals split at creases (crease_normals.h): exact cases on a
// cube and a sphere, then the picture: the cube's faces meet in a sharp
// change of shade, not a smooth blend.
#include "client/viewer/crease_normals.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "client/viewer/camera.h"
#include "client/viewer/offscreen.h"
#include "common/mesh/import.h"
#include "common/mesh/procedural.h"
#include "tests/test_meshes.h"
#include "tests/viewer/cube_edges.h"
#include "tests/viewer/image_checks.h"

namespace meshstream::client {
namespace {

float distance(Vec3f a, Vec3f b) { return length(a - b); }

TEST(CreaseNormals, EveryCubeCornerGetsItsFacesNormal) {
  const Mesh cube = testing::make_cube();
  for (float degrees : {kDefaultShadingCreaseDegrees, 30.0f, 89.0f}) {
    ShadingMesh s = split_normals_at_creases(cube, degrees);
    // Three sides meet at each corner: three copies of every vertex.
    ASSERT_EQ(s.positions.size(), 24u) << degrees;
    ASSERT_EQ(s.normals.size(), 24u);
    ASSERT_EQ(s.copied_from.size(), 16u);
    ASSERT_EQ(s.triangles.size(), cube.triangles.size());
    for (uint32_t f = 0; f < cube.face_count(); ++f) {
      const Vec3f n = face_normal(cube, f);
      for (int k = 0; k < 3; ++k) {
        const uint32_t drawn = s.triangles[f][k];
        // Same place as the input corner, and the face's own normal.
        EXPECT_EQ(distance(s.positions[drawn], cube.positions[cube.triangles[f][k]]), 0.0f);
        EXPECT_LT(distance(s.normals[drawn], n), 1e-6f)
            << "face " << f << " corner " << k << " at " << degrees << " degrees";
      }
    }
    for (size_t i = 0; i < s.copied_from.size(); ++i) {
      EXPECT_EQ(distance(s.positions[8 + i], cube.positions[s.copied_from[i]]), 0.0f);
    }
  }
}

TEST(CreaseNormals, AboveTheEdgeAngleTheCubeStaysSmooth) {
  const Mesh cube = testing::make_cube();
  for (float degrees : {91.0f, 180.0f}) {
    ShadingMesh s = split_normals_at_creases(cube, degrees);
    EXPECT_EQ(s.positions.size(), 8u) << degrees;
    EXPECT_EQ(s.triangles, cube.triangles);
    const auto smooth = compute_vertex_normals(cube);
    for (uint32_t v = 0; v < 8; ++v) EXPECT_LT(distance(s.normals[v], smooth[v]), 1e-6f);
  }
}

TEST(CreaseNormals, ASmoothSurfaceIsNotSplitAndKeepsItsOwnNormals) {
  Mesh sphere = make_icosphere(3);
  sphere.normals = compute_vertex_normals(sphere);
  for (Vec3f& n : sphere.normals) n = normalized(n + Vec3f{0.0f, 0.0f, 1e-3f});  // recognisable
  ShadingMesh s = split_normals_at_creases(sphere, kDefaultShadingCreaseDegrees);
  EXPECT_TRUE(s.copied_from.empty());
  EXPECT_EQ(s.triangles, sphere.triangles);
  ASSERT_EQ(s.normals.size(), sphere.normals.size());
  for (size_t v = 0; v < s.normals.size(); ++v)
    EXPECT_EQ(distance(s.normals[v], sphere.normals[v]), 0.0f);
}

TEST(CreaseNormals, DegenerateFacesAndIsolatedVerticesDoNotSplitOrBreak) {
  Mesh m = testing::make_cube();
  m.positions.push_back({5, 5, 5});  // isolated
  // A zero-area sliver on the top edge (vertices 4, 5 and the edge midpoint
  // would need a new vertex; use a repeated position instead).
  m.positions.push_back({0.5f, 0.0f, 1.0f});
  m.triangles.push_back({4, 9, 5});
  ShadingMesh s = split_normals_at_creases(m, kDefaultShadingCreaseDegrees);
  ASSERT_EQ(s.normals.size(), s.positions.size());
  EXPECT_EQ(distance(s.normals[8], Vec3f{}), 0.0f);  // no faces: no normal
  for (const Vec3f& n : s.normals) EXPECT_TRUE(std::isfinite(n.x + n.y + n.z));
  // The sliver's middle vertex has only the sliver: one group, no copy.
  EXPECT_EQ(std::count(s.copied_from.begin(), s.copied_from.end(), 9u), 0);
  // The sliver on the edge 4-5 does not bridge the crease there: the cube's
  // corners still get their own faces' normals.
  EXPECT_EQ(s.copied_from.size(), 16u);
  for (uint32_t f = 0; f < 12; ++f) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_LT(distance(s.normals[s.triangles[f][k]], face_normal(m, f)), 1e-6f);
    }
  }
}

constexpr int kWidth = 320, kHeight = 240;

RgbaImage render(const Mesh& mesh, float crease_degrees, const std::string& name) {
  OffscreenRequest request;
  request.width = kWidth;
  request.height = kHeight;
  request.crease_degrees = crease_degrees;
  auto image = render_offscreen(mesh, request);
  EXPECT_TRUE(image.has_value()) << (image ? "" : image.error().message);
  if (!image) return {};
  testing::keep_for_inspection(*image, "crease_" + name);
  return *image;
}

TEST(CreaseNormals, SnapshotOfACubeChangesShadeAtEveryEdgeOnlyWhenSplit) {
  const Mesh cube = testing::make_cube();
  RgbaImage sharp = render(cube, 0.0f, "cube_default");  // the default angle
  RgbaImage smooth = render(cube, 180.0f, "cube_never_split");
  ASSERT_FALSE(sharp.rgba.empty());
  ASSERT_FALSE(smooth.rgba.empty());
  const auto sharp_edges = testing::shades_beside_visible_edges(cube, sharp);
  const auto smooth_edges = testing::shades_beside_visible_edges(cube, smooth);
  // Three sides visible, three edges between them.
  ASSERT_EQ(sharp_edges.size(), 3u);
  const int sharp_largest = testing::largest_edge_step(sharp_edges);
  const int smooth_largest = testing::largest_edge_step(smooth_edges);
  // Measured: split, two sides differ by 58 grey levels next to their edge;
  // with one normal per corner by at most 5.
  EXPECT_GE(sharp_largest, 25) << "the cube's edges are not drawn sharp";
  EXPECT_LE(smooth_largest, 10) << "one normal per corner should blend the sides";
}

// The CAD part of issue 21's row 17, when the real meshes are present: its
// machined edges split, and the picture shows it.
TEST(CreaseNormals, FandiskSplitsAtItsMachinedEdges) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  auto mesh = import_mesh(meshstream::testing::test_mesh("fandisk.off"));
  ASSERT_TRUE(mesh.has_value()) << mesh.error().message;
  const ShadingMesh split = split_normals_at_creases(mesh->mesh, kDefaultShadingCreaseDegrees);
  EXPECT_GT(split.copied_from.size(), mesh->mesh.vertex_count() / 50)
      << "fandisk has long sharp edges: more vertices should split";
  RgbaImage sharp = render(mesh->mesh, 0.0f, "fandisk_default");
  RgbaImage smooth = render(mesh->mesh, 180.0f, "fandisk_never_split");
  EXPECT_GT(testing::differing_pixels(sharp, smooth), size_t{kWidth} * kHeight / 50);
}

}  // namespace
}  // namespace meshstream::client
