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
#include "tests/viewer/image_checks.h"

namespace meshstream::client {
namespace {

// The unit cube, 8 shared corners, 12 outward-facing triangles.
Mesh make_cube() {
  Mesh m;
  for (int i = 0; i < 8; ++i) {
    m.positions.push_back(
        {static_cast<float>(i & 1), static_cast<float>((i >> 1) & 1), static_cast<float>(i >> 2)});
  }
  // Each side as a quad (a, b, c, d) counter-clockwise seen from outside.
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

float distance(Vec3f a, Vec3f b) { return length(a - b); }

TEST(CreaseNormals, EveryCubeCornerGetsItsFacesNormal) {
  const Mesh cube = make_cube();
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
  const Mesh cube = make_cube();
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
  Mesh m = make_cube();
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

int luma(const RgbaImage& image, int x, int y) {
  const uint8_t* p = image.pixel(x, y);
  return (299 * p[0] + 587 * p[1] + 114 * p[2]) / 1000;
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

// For every edge of the cube whose two sides both face the camera: the
// brightness of the picture a little inside each side, next to the
// edge's midpoint (the camera render_offscreen uses, rebuilt here).
struct EdgeShades {
  int side_a = 0, side_b = 0;
};

std::vector<EdgeShades> shades_beside_visible_edges(const Mesh& cube, const RgbaImage& image) {
  const OffscreenRequest defaults;
  OrbitCamera camera;
  camera.yaw = defaults.yaw;
  camera.pitch = defaults.pitch;
  const float aspect = static_cast<float>(kWidth) / kHeight;
  camera.frame(cube, aspect, defaults.fill);
  const Mat4 m = mat4_multiply(camera.projection(aspect), camera.view());
  auto pixel_of = [&](Vec3f p) {
    const float x = m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12];
    const float y = m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13];
    const float w = m[3] * p.x + m[7] * p.y + m[11] * p.z + m[15];
    return std::pair<int, int>{static_cast<int>((x / w + 1) / 2 * kWidth),
                               static_cast<int>((1 - y / w) / 2 * kHeight)};
  };
  std::vector<EdgeShades> shades;
  for (uint32_t f = 0; f < cube.face_count(); ++f) {
    for (uint32_t g = f + 1; g < cube.face_count(); ++g) {
      const Vec3f nf = face_normal(cube, f), ng = face_normal(cube, g);
      if (dot(nf, ng) > 0.5f) continue;  // same side of the cube
      std::vector<uint32_t> shared;
      for (uint32_t a : cube.triangles[f])
        for (uint32_t b : cube.triangles[g])
          if (a == b) shared.push_back(a);
      if (shared.size() != 2) continue;
      const Vec3f mid = (cube.positions[shared[0]] + cube.positions[shared[1]]) * 0.5f;
      if (dot(nf, camera.eye() - mid) <= 0 || dot(ng, camera.eye() - mid) <= 0) continue;
      // 3 % of the side into each face: on a cube, into face f is away
      // from the other face's normal.
      const auto [xa, ya] = pixel_of(mid - ng * 0.03f);
      const auto [xb, yb] = pixel_of(mid - nf * 0.03f);
      shades.push_back({luma(image, xa, ya), luma(image, xb, yb)});
    }
  }
  return shades;
}

TEST(CreaseNormals, SnapshotOfACubeChangesShadeAtEveryEdgeOnlyWhenSplit) {
  const Mesh cube = make_cube();
  RgbaImage sharp = render(cube, 0.0f, "cube_default");  // the default angle
  RgbaImage smooth = render(cube, 180.0f, "cube_never_split");
  ASSERT_FALSE(sharp.rgba.empty());
  ASSERT_FALSE(smooth.rgba.empty());
  const auto sharp_edges = shades_beside_visible_edges(cube, sharp);
  const auto smooth_edges = shades_beside_visible_edges(cube, smooth);
  // Three sides visible, three edges between them.
  ASSERT_EQ(sharp_edges.size(), 3u);
  int sharp_largest = 0, smooth_largest = 0;
  for (const EdgeShades& e : sharp_edges) {
    sharp_largest = std::max(sharp_largest, std::abs(e.side_a - e.side_b));
  }
  for (const EdgeShades& e : smooth_edges) {
    smooth_largest = std::max(smooth_largest, std::abs(e.side_a - e.side_b));
  }
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
