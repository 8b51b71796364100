// Creases: with --crease, points made on sharp edges stay on the original
// sharp polyline (curve rule along the crease, corners fixed), while the
// plain scheme rounds them off.
#include <cstdio>
#include <set>

#include "tests/asa/asa_test_support.h"

namespace meshstream {
namespace {

struct Segment {
  Vec3f a, b;
};

float distance_to_segment(Vec3f p, const Segment& s) {
  const Vec3f d = s.b - s.a;
  const float len2 = dot(d, d);
  float u = len2 > 0 ? dot(p - s.a, d) / len2 : 0;
  u = std::clamp(u, 0.0f, 1.0f);
  return length(p - (s.a + d * u));
}

struct CreaseDeviation {
  float max = 0, mean = 0;
  size_t points = 0;
};

// Runs two uniform levels with and without creases and measures how far the
// points made on sharp edges end up from the original sharp polyline.
std::pair<CreaseDeviation, CreaseDeviation> crease_deviation(const Mesh& m, float degrees) {
  auto adj = Adjacency::build(m);
  EXPECT_TRUE(adj.has_value());
  std::vector<Segment> segments;
  std::set<std::pair<uint32_t, uint32_t>> sharp;
  const float cos_limit = std::cos(degrees * 3.14159265f / 180.0f);
  for (uint32_t c = 0; c < adj->corner_count(); ++c) {
    const uint32_t o = adj->opposite(c);
    if (o == kNone || o < c) continue;
    if (dot(face_normal(m, c / 3), face_normal(m, o / 3)) >= cos_limit) continue;
    uint32_t a = adj->vertex(Adjacency::next(c)), b = adj->vertex(Adjacency::prev(c));
    segments.push_back({m.positions[a], m.positions[b]});
    sharp.insert({std::min(a, b), std::max(a, b)});
  }
  EXPECT_FALSE(segments.empty());
  AsaOptions o;
  o.uniform = true;
  o.levels = 1;
  auto one = subdivide(m, o);
  o.levels = 2;
  auto plain = subdivide(m, o);
  o.crease_degrees = degrees;
  auto creased = subdivide(m, o);
  EXPECT_TRUE(asa_test::conforming(m, *creased));
  // Points on sharp edges: level-1 midpoints of sharp edges and the level-2
  // points on their halves (same numbering with and without creases).
  const uint32_t V0 = m.vertex_count(), V1 = one->mesh.vertex_count(),
                 V2 = plain->mesh.vertex_count();
  auto p1 = asa_test::parents(one->mesh.triangles, V0, V1);
  std::set<std::pair<uint32_t, uint32_t>> sharp1;
  std::vector<uint32_t> points;
  for (uint32_t i = 0; i < p1.size(); ++i) {
    auto [a, b] = p1[i];
    if (!sharp.count({std::min(a, b), std::max(a, b)})) continue;
    points.push_back(V0 + i);
    sharp1.insert({std::min(a, V0 + i), std::max(a, V0 + i)});
    sharp1.insert({std::min(b, V0 + i), std::max(b, V0 + i)});
  }
  auto p2 = asa_test::parents(plain->mesh.triangles, V1, V2);
  for (uint32_t i = 0; i < p2.size(); ++i) {
    auto [a, b] = p2[i];
    if (sharp1.count({std::min(a, b), std::max(a, b)})) points.push_back(V1 + i);
  }
  auto measure = [&](const Mesh& out) {
    CreaseDeviation d;
    for (uint32_t v : points) {
      float best = 1e30f;
      for (const Segment& s : segments)
        best = std::min(best, distance_to_segment(out.positions[v], s));
      d.max = std::max(d.max, best);
      d.mean += best;
    }
    d.points = points.size();
    d.mean /= std::max<size_t>(1, points.size());
    return d;
  };
  return {measure(creased->mesh), measure(plain->mesh)};
}

TEST(AsaCrease, FandiskSharpEdgesStaySharp) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  Mesh m = asa_test::load("fandisk.off");
  const float diagonal = bounding_box(m).diagonal();
  auto [creased, plain] = crease_deviation(m, 45.0f);
  std::printf(
      "fandisk, 2 levels, %zu crease points: distance to the sharp polyline / diagonal: "
      "creased max %.2e mean %.2e, plain max %.2e mean %.2e\n",
      creased.points, creased.max / diagonal, creased.mean / diagonal, plain.max / diagonal,
      plain.mean / diagonal);
  EXPECT_GT(creased.points, 500u);
  EXPECT_LT(creased.max, 0.25f * plain.max);
  EXPECT_LT(creased.mean, 0.25f * plain.mean);
  EXPECT_LT(creased.max / diagonal, 2e-3f);
}

TEST(AsaCrease, ChamferCubeEdgesStayStraight) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  Mesh m = asa_test::load("chamfer-cube.off");
  const float diagonal = bounding_box(m).diagonal();
  auto [creased, plain] = crease_deviation(m, 30.0f);
  std::printf("chamfer-cube: creased max %.2e, plain max %.2e of the diagonal\n",
              creased.max / diagonal, plain.max / diagonal);
  EXPECT_LT(creased.max / diagonal, 1e-5f);
  EXPECT_GT(plain.max / diagonal, 1e-3f);
}

// ASA with creases: sharp edges do not ask for refinement by themselves.
TEST(AsaCrease, CreasesDoNotDriveAdaptiveRefinement) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  Mesh m = asa_test::load("fandisk.off");
  AsaOptions o;
  o.levels = 2;
  o.flatness = 0.9f;
  auto plain = subdivide(m, o);
  o.crease_degrees = 45.0f;
  auto creased = subdivide(m, o);
  ASSERT_TRUE(plain.has_value() && creased.has_value());
  EXPECT_TRUE(asa_test::conforming(m, *creased));
  EXPECT_LT(creased->mesh.face_count(), plain->mesh.face_count());
}

}  // namespace
}  // namespace meshstream
