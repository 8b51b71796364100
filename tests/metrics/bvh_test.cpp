#include "common/metrics/bvh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "common/metrics/closest_point.h"
#include "tests/metrics/procedural_meshes.h"

namespace meshstream {
namespace {

double brute_force_squared_distance(const Mesh& m, Vec3d q) {
  double best = std::numeric_limits<double>::infinity();
  for (const Triangle& t : m.triangles) {
    const Vec3d p =
        closest_point_on_triangle(q, to_double(m.positions[t[0]]), to_double(m.positions[t[1]]),
                                  to_double(m.positions[t[2]]));
    best = std::min(best, squared_length(q - p));
  }
  return best;
}

// Random triangles of all sizes, some degenerate, some sharing a centroid.
Mesh triangle_soup(uint32_t count, std::mt19937& rng) {
  std::uniform_real_distribution<float> coord(-10, 10), small(-0.01f, 0.01f);
  Mesh m;
  for (uint32_t i = 0; i < count; ++i) {
    const Vec3f base{coord(rng), coord(rng), coord(rng)};
    const uint32_t v = m.vertex_count();
    if (i % 10 == 0) {  // collinear
      m.positions.push_back(base);
      m.positions.push_back(base + Vec3f{1, 1, 1});
      m.positions.push_back(base + Vec3f{2, 2, 2});
    } else if (i % 10 == 1) {  // same point three times
      m.positions.insert(m.positions.end(), 3, base);
    } else if (i % 10 == 2) {  // all around one shared centroid
      m.positions.push_back({1 + small(rng), 0, 0});
      m.positions.push_back({-0.5f, 0.8f + small(rng), 0});
      m.positions.push_back({-0.5f, -0.8f, small(rng)});
    } else {
      m.positions.push_back(base);
      m.positions.push_back(base + Vec3f{small(rng) * 300, small(rng) * 300, small(rng) * 300});
      m.positions.push_back(base + Vec3f{small(rng) * 300, small(rng) * 300, small(rng) * 300});
    }
    m.triangles.push_back({v, v + 1, v + 2});
  }
  return m;
}

void expect_matches_brute_force(const TriangleBvh& bvh, const Mesh& m,
                                const std::vector<Vec3d>& queries) {
  ASSERT_EQ(bvh.triangle_count(), m.face_count());
  uint32_t hint = TriangleBvh::kNoHint;
  for (const Vec3d& q : queries) {
    const double want = brute_force_squared_distance(m, q);
    const ClosestHit hit = bvh.closest(q);
    ASSERT_EQ(hit.squared_distance, want) << "query " << q.x << " " << q.y << " " << q.z;
    // The reported triangle really is at that distance.
    const Triangle& t = m.triangles[hit.triangle];
    const Vec3d p =
        closest_point_on_triangle(q, to_double(m.positions[t[0]]), to_double(m.positions[t[1]]),
                                  to_double(m.positions[t[2]]));
    EXPECT_EQ(squared_length(q - p), want);
    // A hint (right or wrong) never changes the answer.
    EXPECT_EQ(bvh.closest(q, hint).squared_distance, want);
    hint = hit.triangle;
  }
}

void expect_matches_brute_force(const Mesh& m, const std::vector<Vec3d>& queries) {
  expect_matches_brute_force(TriangleBvh::build(m), m, queries);
}

TEST(TriangleBvh, MatchesBruteForceOnASphere) {
  const Mesh m = testing::icosphere(3);  // 1280 triangles
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-2, 2);
  std::normal_distribution<double> near(0, 1e-6);
  std::vector<Vec3d> queries;
  for (int i = 0; i < 1500; ++i) queries.push_back({coord(rng), coord(rng), coord(rng)});
  // Queries a hair off the surface, where rounding matters most.
  for (int i = 0; i < 500; ++i) {
    const Vec3d p = to_double(m.positions[rng() % m.vertex_count()]);
    const Vec3d o = to_double(m.positions[rng() % m.vertex_count()]);
    queries.push_back(p * 0.9 + o * 0.1 + Vec3d{near(rng), near(rng), near(rng)});
  }
  expect_matches_brute_force(m, queries);
}

TEST(TriangleBvh, MatchesBruteForceOnADegenerateSoup) {
  std::mt19937 rng(11);
  const Mesh m = triangle_soup(3000, rng);
  std::uniform_real_distribution<double> coord(-12, 12);
  std::vector<Vec3d> queries;
  for (int i = 0; i < 1000; ++i) queries.push_back({coord(rng), coord(rng), coord(rng)});
  for (int i = 0; i < 200; ++i) queries.push_back(to_double(m.positions[rng() % m.vertex_count()]));
  expect_matches_brute_force(m, queries);
}

TEST(TriangleBvh, DepthStaysBoundedWhenEveryCentroidCoincides) {
  Mesh m;
  for (uint32_t i = 0; i < 5000; ++i) {  // a fan of triangles all centred on the origin
    const float a = 0.001f * static_cast<float>(i);
    const uint32_t v = m.vertex_count();
    m.positions.push_back({std::cos(a), std::sin(a), 0});
    m.positions.push_back({std::cos(a + 2.0944f), std::sin(a + 2.0944f), 0.5f});
    m.positions.push_back({std::cos(a + 4.1888f), std::sin(a + 4.1888f), -0.5f});
    m.triangles.push_back({v, v + 1, v + 2});
  }
  const TriangleBvh bvh = TriangleBvh::build(m);
  EXPECT_LE(bvh.depth(), 80u);
  std::vector<Vec3d> queries = {{0, 0, 3}, {2, 0, 0}, {0.1, 0.1, 0.1}, {-5, 2, 1}};
  expect_matches_brute_force(m, queries);
}

// Two clusters far apart, 4 and 28 small triangles: the SAH cuts at the gap,
// so the root's left child is one leaf holding exactly the small cluster.
// (Empty bins in between once made every split cost inf or NaN, and the
// build fell back to a median split that mixed the clusters.)
TEST(TriangleBvh, SahSplitsAtTheGapBetweenClusters) {
  Mesh m;
  auto add_triangle = [&](Vec3f at) {
    const uint32_t v = m.vertex_count();
    m.positions.push_back(at);
    m.positions.push_back(at + Vec3f{0.1f, 0, 0});
    m.positions.push_back(at + Vec3f{0, 0.1f, 0});
    m.triangles.push_back({v, v + 1, v + 2});
  };
  for (int i = 0; i < 4; ++i) add_triangle({0.2f * i, 0, 0});
  for (int i = 0; i < 28; ++i) add_triangle({100 + 0.2f * (i % 7), 0.2f * (i / 7), 0});
  const TriangleBvh bvh = TriangleBvh::build(m);
  ASSERT_GE(bvh.node_count(), 3u);
  const TriangleBvh::Node& left = bvh.nodes()[1];
  EXPECT_EQ(left.count(), 4u) << "the root's left child is not the small cluster's leaf";
  EXPECT_LT(left.hi.x, 1.0f);

  // The shape never changes a distance.
  std::vector<Vec3d> queries;
  for (int i = 0; i < 50; ++i) queries.push_back({-5 + 2.5 * i, 0.3 * (i % 5), 1.0 - 0.1 * i});
  expect_matches_brute_force(bvh, m, queries);
}

TEST(TriangleBvh, EmptyMeshGivesEmptyHierarchy) { EXPECT_TRUE(TriangleBvh::build(Mesh{}).empty()); }

TEST(TriangleBvh, BuildIsDeterministic) {
  const Mesh m = testing::icosphere(3);
  const TriangleBvh x = TriangleBvh::build(m), y = TriangleBvh::build(m);
  ASSERT_EQ(x.node_count(), y.node_count());
  EXPECT_EQ(x.depth(), y.depth());
  for (Vec3d q : {Vec3d{0.3, 0.2, 2}, Vec3d{-1, 0, 0.5}}) {
    EXPECT_EQ(x.closest(q).triangle, y.closest(q).triangle);
  }
}

TEST(TriangleBvh, ThreadsBuildTheSameTree) {
  const Mesh m = testing::icosphere(6);  // 81920 triangles: subtrees on their own threads
  const TriangleBvh one = TriangleBvh::build(m, 1), four = TriangleBvh::build(m, 4);
  ASSERT_EQ(one.node_count(), four.node_count());
  EXPECT_EQ(one.depth(), four.depth());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coord(-1.5, 1.5);
  for (int i = 0; i < 2000; ++i) {
    const Vec3d q{coord(rng), coord(rng), coord(rng)};
    const ClosestHit a = one.closest(q), b = four.closest(q);
    ASSERT_EQ(a.squared_distance, b.squared_distance);
    ASSERT_EQ(a.triangle, b.triangle);  // the same tree visits in the same order
  }
}

TEST(TriangleBvh, RefitToNewPositionsIsExact) {
  // Built over one set of positions, refitted to others (moved, scaled and
  // jittered): every query still matches brute force over the new ones.
  const Mesh m = testing::icosphere(3);
  Mesh moved = m;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> jitter(-0.05f, 0.05f);
  for (Vec3f& p : moved.positions)
    p = p * 37.0f + Vec3f{100 + jitter(rng), -3 + jitter(rng), 0.5f + jitter(rng)};
  TriangleBvh bvh = TriangleBvh::build(m);
  ASSERT_TRUE(bvh.refit(moved));
  std::uniform_real_distribution<double> coord(-60, 60);
  std::vector<Vec3d> queries;
  for (int i = 0; i < 1000; ++i)
    queries.push_back(Vec3d{100, -3, 0.5} + Vec3d{coord(rng), coord(rng), coord(rng)});
  for (int i = 0; i < 300; ++i) queries.push_back(to_double(moved.positions[rng() % 642]));
  expect_matches_brute_force(bvh, moved, queries);
  // And back: the original positions again.
  ASSERT_TRUE(bvh.refit(m));
  expect_matches_brute_force(bvh, m, {{0.3, 0.2, 2}, {-1, 0, 0.5}, {0, 0, 0}});
}

// A slot hint is the triangle hint it stands for: the same hit (distance,
// point, triangle, slot) query for query, with the triangle-to-slot map
// dropped too; without the map closest() still gives every distance, and
// restore_triangle_hints() brings its hints back.
TEST(TriangleBvh, SlotHintsGiveTheSameHitsAsTriangleHints) {
  std::mt19937 rng(13);
  const Mesh m = triangle_soup(2000, rng);
  TriangleBvh bvh = TriangleBvh::build(m);
  std::uniform_real_distribution<double> coord(-12, 12);
  std::vector<Vec3d> queries;
  for (int i = 0; i < 600; ++i) queries.push_back({coord(rng), coord(rng), coord(rng)});
  std::vector<ClosestHit> by_triangle;
  uint32_t hint = TriangleBvh::kNoHint;
  for (const Vec3d& q : queries) {
    by_triangle.push_back(bvh.closest(q, hint));
    hint = by_triangle.back().triangle;
  }
  auto expect_slot_hints_match = [&] {
    uint32_t slot = TriangleBvh::kNoHint;
    for (size_t i = 0; i < queries.size(); ++i) {
      const ClosestHit hit = bvh.closest_from_slot(queries[i], slot);
      ASSERT_EQ(hit.squared_distance, by_triangle[i].squared_distance) << i;
      EXPECT_EQ(hit.triangle, by_triangle[i].triangle) << i;
      EXPECT_EQ(hit.slot, by_triangle[i].slot) << i;
      EXPECT_EQ(hit.point.x, by_triangle[i].point.x) << i;
      slot = hit.slot;
    }
  };
  expect_slot_hints_match();
  bvh.drop_triangle_hints();
  expect_slot_hints_match();
  for (size_t i = 0; i < queries.size(); ++i)
    ASSERT_EQ(bvh.closest(queries[i], i ? by_triangle[i - 1].triangle : TriangleBvh::kNoHint)
                  .squared_distance,
              by_triangle[i].squared_distance);
  bvh.restore_triangle_hints();
  hint = TriangleBvh::kNoHint;
  for (size_t i = 0; i < queries.size(); ++i) {
    const ClosestHit hit = bvh.closest(queries[i], hint);
    EXPECT_EQ(hit.triangle, by_triangle[i].triangle) << i;
    EXPECT_EQ(hit.slot, by_triangle[i].slot) << i;
    hint = hit.triangle;
  }
}

TEST(TriangleBvh, RefitRefusesOtherTriangleCounts) {
  const Mesh m = testing::icosphere(1);
  TriangleBvh bvh = TriangleBvh::build(m);
  Mesh fewer = m;
  fewer.triangles.pop_back();
  const auto st = bvh.refit(fewer);
  ASSERT_FALSE(st);
  EXPECT_EQ(st.error().code, ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace meshstream
