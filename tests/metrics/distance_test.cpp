#include "common/metrics/distance.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/metrics/surface_sampling.h"
#include "tests/metrics/procedural_meshes.h"

namespace meshstream {
namespace {

using testing::grid_square;
using testing::icosphere;
using testing::scaled;

DistanceOptions few_samples(uint32_t samples = 20000, uint32_t threads = 0) {
  DistanceOptions o;
  o.samples = samples;
  o.threads = threads;
  return o;
}

TEST(SurfaceDistance, AMeshAgainstItselfIsZero) {
  const Mesh m = icosphere(3);
  auto d = surface_distance(m, m, few_samples());
  ASSERT_TRUE(d) << d.error().message;
  // Zero up to the rounding of projecting a sample onto its own triangle.
  EXPECT_LE(d->hausdorff, 1e-14);
  EXPECT_LE(d->rms, 1e-14);
  EXPECT_LE(d->a_to_b.mean, 1e-14);
  EXPECT_NEAR(d->diagonal, 2 * std::sqrt(3.0), 1e-5);
}

TEST(SurfaceDistance, ShiftedSquareIsAtTheShiftEverywhere) {
  const double shift = 0.25;
  const Mesh a = grid_square(4, 0);
  const Mesh b = grid_square(7, static_cast<float>(shift));  // another tessellation
  auto d = surface_distance(a, b, few_samples());
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_NEAR(d->hausdorff, shift, 1e-12);
  EXPECT_NEAR(d->rms, shift, 1e-12);
  EXPECT_NEAR(d->a_to_b.mean, shift, 1e-12);
  EXPECT_NEAR(d->b_to_a.max, shift, 1e-12);
  EXPECT_NEAR(d->relative_hausdorff(), shift / std::sqrt(2.0), 1e-7);
}

// A unit square, plus two small separate triangles far from it: the original.
// The "decoded" copy keeps the square and folds the first small triangle to
// a segment and the second to a point, as 12-bit quantization does on dense
// scans. `same_index` writes the folds as repeated indices (what welding
// makes of them), otherwise as distinct vertices at one position (what a
// decoder writes).
struct FoldedPair {
  Mesh original, folded;
};

FoldedPair folded_components(bool same_index) {
  FoldedPair p;
  p.original = grid_square(2, 0);
  p.folded = p.original;
  auto add = [](Mesh& m, std::initializer_list<Vec3f> corners) {
    const uint32_t first = m.vertex_count();
    for (const Vec3f& c : corners) m.positions.push_back(c);
    m.triangles.push_back({first, first + 1, first + 2});
  };
  // Far to the side (x = 10 and x = 20), 0.1 across.
  add(p.original, {{10, 0, 0}, {10.1f, 0, 0}, {10, 0.1f, 0}});
  add(p.original, {{20, 0, 0}, {20.1f, 0, 0}, {20, 0.1f, 0}});
  const Vec3f on_segment{10.05f, 0, 0};
  const Vec3f point{20.03f, 0.03f, 0};
  if (same_index) {
    const uint32_t s = p.folded.vertex_count();
    p.folded.positions.push_back({10, 0, 0});
    p.folded.positions.push_back({10.1f, 0, 0});
    p.folded.triangles.push_back({s, s + 1, s + 1});  // the segment
    p.folded.positions.push_back(point);
    p.folded.triangles.push_back({s + 2, s + 2, s + 2});  // the point
  } else {
    add(p.folded, {{10, 0, 0}, {10.1f, 0, 0}, on_segment});
    add(p.folded, {point, point, point});
  }
  return p;
}

// The farthest point of a small original triangle from its folded copy is a
// corner (distance to a convex set is convex): (10, 0.1) to the segment on
// the x axis, and the corners (20.1, 0) and (20, 0.1) to the point.
double expected_folded_distance() {
  auto d = [](double x, double y, double px, double py) { return std::hypot(x - px, y - py); };
  const float f01 = 0.1f, f201 = 20.1f, f2003 = 20.03f, f003 = 0.03f;
  const double to_segment = f01;
  const double to_point = std::max(d(f201, 0, f2003, f003), d(20, f01, f2003, f003));
  return std::max(to_segment, to_point);
}

TEST(SurfaceDistance, AFoldedTriangleCountsAsItsSegmentOrPoint) {
  for (bool same_index : {false, true}) {
    const FoldedPair p = folded_components(same_index);
    auto d = surface_distance(p.original, p.folded, few_samples());
    ASSERT_TRUE(d) << d.error().message;
    // Were the folded faces dropped, the small triangles would be measured
    // against the square, about 9 and 19 away.
    EXPECT_NEAR(d->a_to_b.max, expected_folded_distance(), 1e-6) << same_index;
    // The folded copy lies on the original: its segment and point are inside
    // the original triangles.
    EXPECT_LE(d->b_to_a.max, 1e-6) << same_index;
    // The point and the segment are targets of their own, not only samples.
    const TriangleBvh bvh = TriangleBvh::build(p.folded);
    const ClosestHit near_point = bvh.closest({20.03, 0.03, 1});
    EXPECT_NEAR(near_point.squared_distance, 1.0, 1e-9) << same_index;
    const ClosestHit near_segment = bvh.closest({10.02, -0.5, 0});
    EXPECT_NEAR(near_segment.squared_distance, 0.25, 1e-9) << same_index;
  }
}

TEST(SurfaceDistance, SphereAgainstItsScaledCopyIsTheRadialGap) {
  // Vertices lie on the spheres of radius 1 and 1.1; the flat facets sit at
  // most 1 - cos(0.04) < 1e-3 inside them, which bounds the deviation.
  const Mesh a = icosphere(4);
  const Mesh b = scaled(a, 1.1f);
  auto d = surface_distance(a, b, few_samples(50000));
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_NEAR(d->hausdorff, 0.1, 1.5e-3);
  EXPECT_NEAR(d->rms, 0.1, 1.5e-3);
  EXPECT_LE(d->a_to_b.rms, d->a_to_b.max);
  EXPECT_LE(d->a_to_b.mean, d->a_to_b.rms);
}

TEST(SurfaceDistance, AsymmetricCoverageIsSeenFromTheLargerSide) {
  // A = [0,1]^2, B = [0,2]x[0,1] in the same plane: A lies on B, but half of B
  // is x - 1 away from A: Hausdorff 1 (B's far corners), RMS sqrt(1/6).
  const Mesh a = grid_square(4);
  Mesh b = grid_square(8);
  for (Vec3f& p : b.positions) p.x *= 2;
  auto d = surface_distance(a, b, few_samples(100000));
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_NEAR(d->a_to_b.max, 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(d->b_to_a.max, 1.0);
  EXPECT_DOUBLE_EQ(d->hausdorff, 1.0);
  EXPECT_NEAR(d->b_to_a.rms, std::sqrt(1.0 / 6.0), 2e-3);
  EXPECT_NEAR(d->b_to_a.mean, 0.25, 2e-3);
  EXPECT_EQ(d->rms, d->b_to_a.rms);
}

TEST(SurfaceDistance, DeterministicForASeedWhateverTheThreads) {
  const Mesh a = icosphere(4);
  Mesh b = icosphere(2);
  for (Vec3f& p : b.positions) p.z *= 1.3f;
  auto one = surface_distance(a, b, few_samples(30000, 1));
  auto two = surface_distance(a, b, few_samples(30000, 2));
  auto five = surface_distance(a, b, few_samples(30000, 5));
  ASSERT_TRUE(one && two && five);
  for (const auto* d : {&*two, &*five}) {
    EXPECT_EQ(d->hausdorff, one->hausdorff);
    EXPECT_EQ(d->rms, one->rms);
    EXPECT_EQ(d->a_to_b.mean, one->a_to_b.mean);
    EXPECT_EQ(d->b_to_a.mean, one->b_to_a.mean);
  }
  // Another seed samples other points: the estimate moves, a little.
  DistanceOptions other = few_samples(30000, 1);
  other.seed = 99;
  auto moved = surface_distance(a, b, other);
  ASSERT_TRUE(moved);
  EXPECT_NE(moved->a_to_b.mean, one->a_to_b.mean);
  EXPECT_NEAR(moved->rms, one->rms, 0.02 * one->rms);
}

TEST(SurfaceDistance, PreparedSurfacesGiveTheSameResult) {
  const Mesh a = icosphere(3);
  const Mesh b = scaled(icosphere(2), 1.05f);
  const DistanceOptions options = few_samples(10000);
  auto direct = surface_distance(a, b, options);
  auto pa = PreparedSurface::prepare(a, options);
  auto pb = PreparedSurface::prepare(b, options);
  ASSERT_TRUE(direct && pa && pb);
  const SurfaceDistance prepared = surface_distance(*pa, *pb);
  EXPECT_EQ(prepared.hausdorff, direct->hausdorff);
  EXPECT_EQ(prepared.rms, direct->rms);
  EXPECT_EQ(prepared.diagonal, direct->diagonal);
}

TEST(SurfaceDistance, EmptyMeshIsAnInvalidArgument) {
  const Mesh m = icosphere(1);
  Mesh empty;
  Mesh points_only;
  points_only.positions = {{0, 0, 0}, {1, 0, 0}};
  for (const Mesh* bad : {&empty, &points_only}) {
    auto ab = surface_distance(m, *bad);
    ASSERT_FALSE(ab);
    EXPECT_EQ(ab.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(ab.error().message.find("mesh B"), std::string::npos) << ab.error().message;
    auto ba = surface_distance(*bad, m);
    ASSERT_FALSE(ba);
    EXPECT_EQ(ba.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(ba.error().message.find("mesh A"), std::string::npos) << ba.error().message;
  }
}

TEST(SurfaceDistance, BadIndicesAndNonFiniteCoordinatesAreRefused) {
  const Mesh m = icosphere(1);
  Mesh bad_index = m;
  bad_index.triangles[3][1] = 1000;
  auto d = surface_distance(m, bad_index);
  ASSERT_FALSE(d);
  EXPECT_EQ(d.error().code, ErrorCode::kInvalidMesh);
  Mesh nan = m;
  nan.positions[2].y = std::nanf("");
  d = surface_distance(nan, m);
  ASSERT_FALSE(d);
  EXPECT_EQ(d.error().code, ErrorCode::kInvalidMesh);
}

TEST(SurfaceSampling, SpreadsSamplesByAreaAndAddsVerticesAndMidpoints) {
  // Two triangles, areas 1/2 and 3/2 (a 1x1 and a 3x1 right triangle side by side).
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {4, 0, 0}};
  m.triangles = {{0, 1, 2}, {1, 3, 2}};
  const SurfaceSamples s = sample_surface(m, 1000, 5);
  ASSERT_EQ(s.area_count, 1000u);
  EXPECT_DOUBLE_EQ(s.area, 2.0);
  EXPECT_EQ(s.points.size(), 1000u + 4 + 5);  // 4 vertices, 5 unique edges
  uint32_t in_first = 0;
  for (uint32_t i = 0; i < s.area_count; ++i) {
    const Vec3d p = s.points[i];
    EXPECT_EQ(p.z, 0.0);
    if (p.x + p.y <= 1) ++in_first;
  }
  // Systematic sampling: the share is exact up to one sample.
  EXPECT_NEAR(in_first, 250, 1);
  // Same seed, same points.
  EXPECT_EQ(sample_surface(m, 1000, 5).points[17].x, s.points[17].x);
}

}  // namespace
}  // namespace meshstream
