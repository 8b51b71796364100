// ASA carries per-corner attributes (corner_attributes.h): a seamed UV
// sphere keeps its seam through subdivision (corners of one vertex on the two
// sides of the seam keep u = 0 and u = 1, nothing smeared in between), the
// corner arrays stay valid at every level, per-face normals stay per face
// (hard edges stay hard), and face materials follow their faces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/asa/subdivide.h"
#include "common/mesh/textured_sphere.h"

namespace meshstream {
namespace {

// Every corner's u against the longitude of its vertex, modulo 1: within
// 1.5 segments (Butterfly moves vertices a little), except near the poles,
// where longitude means little; a seam smeared by per-vertex averaging
// gives u near 0.5 at phi = 0. And within every face the corners' u span
// less than a half: a face that took a corner from the seam's other side
// mixes u near 0 with u near 1. Returns the corners checked at vertices
// within 0.01 radians of the seam (phi = 0).
int check_seam(const Mesh& m, uint32_t segments) {
  const double two_pi = 2 * 3.14159265358979323846;
  int seam = 0;
  for (uint32_t f = 0; f < m.face_count(); ++f) {
    const Triangle& t = m.triangles[f];
    float lo = 1, hi = 0;
    for (int k = 0; k < 3; ++k) {
      const float u = m.corner_texcoords.at_corner(3 * size_t(f) + k).x;
      lo = std::min(lo, u);
      hi = std::max(hi, u);
      const Vec3f p = m.positions[t[k]];
      if (std::abs(p.z) > 0.95f) continue;
      const double phi = std::atan2(double(p.y), double(p.x));
      seam += std::abs(phi) < 0.01;
      double off = double(u) - phi / two_pi;
      off -= std::round(off);
      EXPECT_LT(std::abs(off), 1.5 / segments) << "face " << f << " corner " << k << " u " << u;
    }
    EXPECT_LT(hi - lo, 0.5f) << "face " << f << " mixes the seam's two sides";
  }
  return seam;
}

TEST(AsaCornerAttributes, SubdividingASeamedSphereKeepsTheSeam) {
  const Mesh sphere = make_textured_uv_sphere(8, 16, 16);
  ASSERT_TRUE(check_attribute_counts(sphere));
  ASSERT_GT(check_seam(sphere, 16), 0);
  for (bool uniform : {true, false}) {
    int previous_seam = check_seam(sphere, 16);
    for (int levels = 1; levels <= 3; ++levels) {
      AsaOptions options;
      options.levels = levels;
      options.uniform = uniform;
      auto result = subdivide(sphere, options);
      ASSERT_TRUE(result) << result.error().message;
      const Mesh& m = result->mesh;
      EXPECT_TRUE(check_attribute_counts(m)) << check_attribute_counts(m).error().message;
      ASSERT_EQ(m.corner_texcoords.corners.size(), 3 * size_t(m.face_count()));
      EXPECT_EQ(m.face_materials.size(), m.face_count());
      EXPECT_TRUE(result->source_face.empty()) << "only tracked when asked";
      const int seam = check_seam(m, 16);
      if (uniform) {
        EXPECT_GT(seam, previous_seam) << "new vertices on the seam edges";
      }
      previous_seam = seam;
      // Every texture coordinate in the sphere's chart.
      for (const Vec2f& uv : m.corner_texcoords.values) {
        EXPECT_GE(uv.x, 0.0f);
        EXPECT_LE(uv.x, 1.0f);
        EXPECT_GE(uv.y, 0.0f);
        EXPECT_LE(uv.y, 1.0f);
      }
    }
  }
}

TEST(AsaCornerAttributes, PerFaceNormalsAndMaterialsFollowTheirFaces) {
  // A cube with a normal per face (the hard-edged export of glTF/OBJ) and
  // a material per side.
  Mesh cube;
  for (int i = 0; i < 8; ++i)
    cube.positions.push_back({float(i & 1), float((i >> 1) & 1), float(i >> 2)});
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  const Vec3f side_normals[6] = {{0, 0, -1}, {0, 0, 1},  {0, -1, 0},
                                 {0, 1, 0},  {-1, 0, 0}, {1, 0, 0}};
  for (int q = 0; q < 6; ++q) {
    cube.triangles.push_back({quads[q][0], quads[q][1], quads[q][2]});
    cube.triangles.push_back({quads[q][0], quads[q][2], quads[q][3]});
    cube.corner_normals.values.push_back(side_normals[q]);
    for (int c = 0; c < 6; ++c) cube.corner_normals.corners.push_back(uint32_t(q));
    cube.face_materials.push_back(uint32_t(q % 2));
    cube.face_materials.push_back(uint32_t(q % 2));
  }
  cube.materials.resize(2);
  ASSERT_TRUE(check_attribute_counts(cube));
  AsaOptions options;
  options.levels = 2;
  options.uniform = true;
  options.track_source_faces = true;
  auto result = subdivide(cube, options);
  ASSERT_TRUE(result) << result.error().message;
  const Mesh& m = result->mesh;
  ASSERT_TRUE(check_attribute_counts(m));
  ASSERT_EQ(result->source_face.size(), m.face_count());
  for (uint32_t f = 0; f < m.face_count(); ++f) {
    const uint32_t s = result->source_face[f];
    EXPECT_EQ(m.face_materials[f], cube.face_materials[s]);
    const Vec3f want = side_normals[s / 2];
    for (int k = 0; k < 3; ++k) {
      const Vec3f n = m.corner_normals.at_corner(3 * size_t(f) + k);
      EXPECT_NEAR(n.x, want.x, 1e-6f);
      EXPECT_NEAR(n.y, want.y, 1e-6f);
      EXPECT_NEAR(n.z, want.z, 1e-6f);
    }
  }
}

}  // namespace
}  // namespace meshstream
