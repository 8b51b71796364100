// Procedural meshes: the topology each promises, outward orientation, and
// determinism.
#include "common/mesh/procedural.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "common/mesh/corner_data.h"
#include "common/mesh/topology.h"
#include "tests/mesh/mesh_invariants.h"

namespace meshstream {
namespace {

struct Expected {
  uint32_t components, boundary_loops, boundary_edges;
  int64_t genus;
};

void expect_topology(const Mesh& mesh, const Expected& e, const char* label) {
  ASSERT_TRUE(validate_arrays(mesh)) << label;
  const MeshStats s = compute_stats(mesh);
  EXPECT_TRUE(s.manifold) << label;
  EXPECT_EQ(s.orientation_conflicts, 0u) << label;
  EXPECT_EQ(s.duplicate_faces, 0u) << label;
  EXPECT_EQ(s.isolated_vertices, 0u) << label;
  EXPECT_EQ(s.components, e.components) << label;
  EXPECT_EQ(s.boundary_loops, e.boundary_loops) << label;
  EXPECT_EQ(s.boundary_edges, e.boundary_edges) << label;
  ASSERT_TRUE(s.genus_valid) << label;
  EXPECT_EQ(s.genus, e.genus) << label;
}

TEST(Procedural, IcosahedronIsTheRegularOne) {
  const Mesh m = make_icosahedron();
  EXPECT_EQ(m.vertex_count(), 12u);
  EXPECT_EQ(m.face_count(), 20u);
  expect_topology(m, {1, 0, 0, 0}, "icosahedron");
  for (const Vec3f& p : m.positions) EXPECT_NEAR(length(p), 1.0f, 1e-6f);
  EXPECT_GT(testing::signed_volume(m), 0);
}

TEST(Procedural, IcosphereQuadruplesFaces) {
  for (uint32_t s = 0; s <= 4; ++s) {
    const Mesh m = make_icosphere(s);
    EXPECT_EQ(m.face_count(), 20u << (2 * s));
    EXPECT_EQ(m.vertex_count(), 10u * (1u << (2 * s)) + 2);
    expect_topology(m, {1, 0, 0, 0}, "icosphere");
    EXPECT_GT(testing::signed_volume(m), 0);
  }
}

TEST(Procedural, OpenGridHasOneBoundaryLoop) {
  const Mesh m = make_open_grid(10);
  EXPECT_EQ(m.face_count(), 200u);
  expect_topology(m, {1, 1, 40, 0}, "grid");
  EXPECT_GT(face_normal(m, 0).z, 0.5f);  // faces +z
}

TEST(Procedural, MultiComponentCountsComponents) {
  const Mesh m = make_multi_component(5);
  EXPECT_EQ(m.face_count(), 5u * 80u);
  expect_topology(m, {5, 0, 0, 0}, "components");
  EXPECT_GT(testing::signed_volume(m), 0);
}

TEST(Procedural, TorusHasGenusOne) {
  const Mesh m = make_torus(30, 12);
  EXPECT_EQ(m.face_count(), 720u);
  expect_topology(m, {1, 0, 0, 1}, "torus");
  EXPECT_GT(testing::signed_volume(m), 0);
}

TEST(Procedural, DemoMeshIsAClosedKnottedTorusNearTheTargetSize) {
  for (uint32_t target : {1000u, 20000u, 200000u}) {
    const Mesh m = make_demo_mesh(target);
    EXPECT_NEAR(static_cast<double>(m.face_count()), target, 0.05 * target) << target;
    expect_topology(m, {1, 0, 0, 1}, "demo");
    EXPECT_GT(testing::signed_volume(m), 0) << "faces must point outwards";
  }
}

TEST(Procedural, DemoMeshIsDeterministic) {
  const Mesh a = make_demo_mesh(10000), b = make_demo_mesh(10000);
  ASSERT_EQ(a.vertex_count(), b.vertex_count());
  EXPECT_EQ(std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vec3f)),
            0);
  EXPECT_TRUE(a.triangles == b.triangles);
}

TEST(Procedural, DemoMeshHasNoSliversOrSpikes) {
  // The displacement must not fold the surface: every triangle keeps a real
  // area and a sane shape, which the codec's decimation relies on.
  const Mesh m = make_demo_mesh(50000);
  double min_ratio = 1.0;
  for (uint32_t f = 0; f < m.face_count(); ++f) {
    const Triangle& t = m.triangles[f];
    const Vec3d a = to_double(m.positions[t[0]]), b = to_double(m.positions[t[1]]),
                c = to_double(m.positions[t[2]]);
    const double area = 0.5 * length(cross(b - a, c - a));
    const double longest =
        std::max({squared_length(b - a), squared_length(c - b), squared_length(a - c)});
    // 1 for the equilateral triangle, 0 for a degenerate one.
    min_ratio = std::min(min_ratio, area / (longest * std::sqrt(3.0) / 4));
  }
  EXPECT_GT(min_ratio, 0.05);
  const BoundingBox box = bounding_box(m);
  EXPECT_GT(box.diagonal(), 2.0f);
  EXPECT_LT(box.diagonal(), 5.0f);
}

TEST(Procedural, FacetedCubeHasNormalSeamsOnItsEdges) {
  for (uint32_t n : {1u, 3u}) {
    const Mesh m = make_faceted_cube(n);
    EXPECT_EQ(m.face_count(), 12 * n * n);
    EXPECT_EQ(m.vertex_count(), 6 * n * n + 2);
    expect_topology(m, {1, 0, 0, 0}, "faceted cube");
    ASSERT_TRUE(check_attribute_counts(m));
    EXPECT_GT(testing::signed_volume(m), 0);
    EXPECT_TRUE(m.normals.empty());
    EXPECT_EQ(m.colors.size(), m.vertex_count());
    EXPECT_EQ(m.corner_normals.values.size(), 6 * (n + 1) * (n + 1));
    // Every corner's normal is its face's normal (flat shading).
    for (uint32_t f = 0; f < m.face_count(); ++f) {
      for (uint32_t k = 0; k < 3; ++k) {
        const Vec3f normal = m.corner_normals.at_corner(3 * f + k);
        EXPECT_GT(dot(normal, face_normal(m, f)), 0.999f);
      }
    }
    // The seams are the cube's 12 edges: 12 * (n - 1) edge points and 8 corners.
    EXPECT_EQ(count_seam_vertices(m, m.corner_normals), 12 * (n - 1) + 8);
    EXPECT_EQ(count_seam_vertices(m, m.corner_texcoords), 12 * (n - 1) + 8);
  }
}

TEST(Procedural, UvSphereHasOneMeridianSeamAndPoles) {
  const uint32_t s = 16, r = 8;
  const Mesh m = make_uv_sphere(s, r);
  EXPECT_EQ(m.face_count(), 2 * s * (r - 1));
  EXPECT_EQ(m.vertex_count(), s * (r - 1) + 2);
  expect_topology(m, {1, 0, 0, 0}, "uv sphere");
  ASSERT_TRUE(check_attribute_counts(m));
  EXPECT_GT(testing::signed_volume(m), 0);
  EXPECT_EQ(m.normals.size(), m.vertex_count());
  ASSERT_FALSE(m.corner_texcoords.empty());
  // The meridian's r - 1 ring vertices and the two poles.
  EXPECT_EQ(count_seam_vertices(m, m.corner_texcoords), (r - 1) + 2);
  for (uint32_t c = 0; c < 3 * m.face_count(); ++c) {
    const Vec2f uv = m.corner_texcoords.at_corner(c);
    EXPECT_GE(uv.x, 0.0f);
    EXPECT_LE(uv.x, 1.0f);
    // v follows the latitude: z = cos(pi v).
    const Vec3f p = m.positions[m.triangles[c / 3][c % 3]];
    EXPECT_NEAR(p.z, std::cos(3.14159265358979 * uv.y), 1e-5);
  }
}

}  // namespace
}  // namespace meshstream
