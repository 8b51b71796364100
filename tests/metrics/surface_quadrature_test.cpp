#include "common/metrics/surface_quadrature.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/metrics/procedural_meshes.h"

namespace meshstream {
namespace {
using testing::grid_square;
using testing::icosphere;

// The weights are the area, at any density.
TEST(SurfaceQuadrature, WeightsSumToTheArea) {
  const Mesh sphere = icosphere(3, 2.0f);
  double area = 0;
  for (const Triangle& t : sphere.triangles) {
    auto d = [&](uint32_t v) {
      return Vec3d{sphere.positions[v].x, sphere.positions[v].y, sphere.positions[v].z};
    };
    const Vec3d n = cross(d(t[1]) - d(t[0]), d(t[2]) - d(t[0]));
    area += 0.5 * std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
  }
  for (double cell : {1e9, 1e-2, 1e-4}) {
    const WeightedSamples s = quadrature_samples(sphere, cell);
    double sum = 0;
    for (double w : s.weights) sum += w;
    EXPECT_NEAR(sum, area, 1e-9 * area) << cell;
    EXPECT_NEAR(s.area, area, 1e-9 * area) << cell;
    EXPECT_GE(s.points.size(), sphere.triangles.size()) << cell;
  }
}

// A plane at constant distance: every point is exactly that far away.
TEST(SurfaceQuadrature, ParallelPlanesAreTheirOffsetApart) {
  const Mesh low = grid_square(8, 0.0f), high = grid_square(3, 0.25f);
  const TriangleBvh to = TriangleBvh::build(low);
  EXPECT_NEAR(weighted_rms_distance(quadrature_samples(high, 1e-3), to), 0.25, 1e-6);
}

// Points depend on the triangle alone: adding a far-away triangle leaves
// the others' points as they were, so two meshes sharing triangles differ
// only by what they do not share (the reason for this sampler).
TEST(SurfaceQuadrature, SharedTrianglesGetTheSamePoints) {
  Mesh a = grid_square(4);
  const WeightedSamples before = quadrature_samples(a, 1e-3);
  const uint32_t base = a.vertex_count();
  a.positions.push_back({5, 5, 1});
  a.positions.push_back({6, 5, 1});
  a.positions.push_back({5, 6, 1});
  a.triangles.push_back({base, base + 1, base + 2});
  const WeightedSamples after = quadrature_samples(a, 1e-3);
  ASSERT_GT(after.points.size(), before.points.size());
  for (size_t i = 0; i < before.points.size(); ++i) {
    EXPECT_EQ(after.points[i].x, before.points[i].x);
    EXPECT_EQ(after.points[i].y, before.points[i].y);
    EXPECT_EQ(after.points[i].z, before.points[i].z);
    EXPECT_EQ(after.weights[i], before.weights[i]);
  }
}

TEST(SurfaceQuadrature, ZeroAreaTrianglesGetNoPoints) {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  m.triangles = {{0, 1, 2}};
  EXPECT_TRUE(quadrature_samples(m, 1e-3).points.empty());
}

}  // namespace
}  // namespace meshstream
