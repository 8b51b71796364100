// Uniform modified Butterfly: counts, conformity, precision of the stencils,
// attributes, options.
#include <cmath>

#include "tests/asa/asa_test_support.h"

namespace meshstream {
namespace {

AsaOptions uniform(int levels) {
  AsaOptions o;
  o.uniform = true;
  o.levels = levels;
  return o;
}

TEST(AsaUniform, IcosahedronCounts) {
  Mesh m = asa_test::icosahedron();
  auto one = subdivide(m, uniform(1));
  ASSERT_TRUE(one.has_value());
  EXPECT_EQ(one->mesh.vertex_count(), 12u + 30u);
  EXPECT_EQ(one->mesh.face_count(), 80u);
  auto two = subdivide(m, uniform(2));
  ASSERT_TRUE(two.has_value());
  EXPECT_EQ(two->mesh.vertex_count(), 42u + 120u);
  EXPECT_EQ(two->mesh.face_count(), 320u);
  EXPECT_TRUE(asa_test::conforming(m, *one));
  EXPECT_TRUE(asa_test::conforming(m, *two));
  for (FaceKind k : two->face_kind) EXPECT_EQ(k, FaceKind::kTarget);
}

TEST(AsaUniform, RealMeshCountsAreVPlusEAndFourF) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  for (const char* name : {"fandisk.off", "hemisphere.off", "casting.off"}) {
    Mesh m = asa_test::load(name);
    Mesh current = m;
    for (int level = 1; level <= 2; ++level) {
      auto r = subdivide(m, uniform(level));
      ASSERT_TRUE(r.has_value()) << name;
      EXPECT_EQ(r->mesh.vertex_count(), current.vertex_count() + asa_test::edge_count(current))
          << name;
      EXPECT_EQ(r->mesh.face_count(), 4 * current.face_count()) << name;
      EXPECT_TRUE(asa_test::conforming(m, *r)) << name;
      current = r->mesh;
    }
  }
}

// The stencil weights sum to one and reproduce linear functions, boundary
// and extraordinary rules included: a tilted plane stays a plane.
TEST(AsaUniform, PlaneStaysPlane) {
  Mesh m = asa_test::grid(6, [](float x, float y) { return 0.25f * x - 0.5f * y + 1.0f; });
  // Alternate the diagonals of every other square ("union jack"): interior
  // valences become 4 and 8, so the extraordinary rules are exercised.
  for (uint32_t s = 0; s < m.face_count(); s += 2) {
    const uint32_t q = s / 2, i = q % 6, j = q / 6;
    if ((i + j) % 2 == 0) continue;
    const uint32_t a = j * 7 + i, b = a + 1, c = a + 8, d = a + 7;
    m.triangles[s] = {a, b, d};
    m.triangles[s + 1] = {b, c, d};
  }
  auto r = subdivide(m, uniform(2));
  ASSERT_TRUE(r.has_value());
  for (const Vec3f& p : r->mesh.positions) EXPECT_NEAR(p.z, 0.25f * p.x - 0.5f * p.y + 1.0f, 1e-5f);
  EXPECT_TRUE(asa_test::conforming(m, *r));
}

// The regular ten-point stencil reproduces quadratics for any tension when
// its far points d lie on the edge's line (Zorin et al. 1996): check it on
// edges whose whole stencil is interior.
TEST(AsaUniform, RegularStencilHasQuadraticPrecision) {
  auto height = [](float x, float y) { return 0.1f * x * x + 0.05f * x * y - 0.08f * y * y; };
  Mesh m = asa_test::grid(10, height);
  for (float tension : {0.0f, 0.05f, -0.03f}) {
    AsaOptions o = uniform(1);
    o.tension = tension;
    auto r = subdivide(m, o);
    ASSERT_TRUE(r.has_value());
    auto par = asa_test::parents(r->mesh.triangles, m.vertex_count(), r->mesh.vertex_count());
    int checked = 0;
    for (uint32_t i = 0; i < par.size(); ++i) {
      const Vec3f a = m.positions[par[i][0]], b = m.positions[par[i][1]];
      auto inner = [](Vec3f p) { return p.x >= 2 && p.x <= 8 && p.y >= 2 && p.y <= 8; };
      if (!inner(a) || !inner(b)) continue;
      const Vec3f p = r->mesh.positions[m.vertex_count() + i];
      EXPECT_NEAR(p.x, (a.x + b.x) / 2, 1e-5f);
      EXPECT_NEAR(p.z, height(p.x, p.y), 1e-4f) << "tension " << tension;
      ++checked;
    }
    EXPECT_GT(checked, 100);
  }
}

TEST(AsaUniform, ColorsAndTexcoordsInterpolatedNormalsRecomputed) {
  Mesh m = asa_test::icosahedron();
  for (uint32_t v = 0; v < m.vertex_count(); ++v) {
    m.colors.push_back({v / 12.0f, 1.0f - v / 12.0f, 0.5f, 1.0f});
    m.texcoords.push_back({v / 12.0f, 0.25f});
  }
  m.normals = compute_vertex_normals(m);
  auto r = subdivide(m, uniform(2));
  ASSERT_TRUE(r.has_value());
  const Mesh& out = r->mesh;
  ASSERT_EQ(out.colors.size(), out.positions.size());
  ASSERT_EQ(out.texcoords.size(), out.positions.size());
  ASSERT_EQ(out.normals.size(), out.positions.size());
  for (uint32_t v = 0; v < m.vertex_count(); ++v) EXPECT_EQ(out.colors[v], m.colors[v]);
  auto par = asa_test::parents(out.triangles, 42, out.vertex_count());
  auto level1 = subdivide(m, uniform(1));
  for (uint32_t i = 0; i < par.size(); ++i) {
    const Vec4f a = level1->mesh.colors[par[i][0]], b = level1->mesh.colors[par[i][1]];
    EXPECT_FLOAT_EQ(out.colors[42 + i].x, (a.x + b.x) / 2);
    EXPECT_FLOAT_EQ(
        out.texcoords[42 + i].x,
        (level1->mesh.texcoords[par[i][0]].x + level1->mesh.texcoords[par[i][1]].x) / 2);
  }
  for (uint32_t v = 0; v < out.vertex_count(); ++v) {
    // On this sphere-like shape the normal points away from the centre.
    EXPECT_GT(dot(out.normals[v], normalized(out.positions[v])), 0.8f);
  }
}

// The projection rule moves a new vertex only along the averaged normal of
// its edge: on a plane with irregular in-plane spacing it gives midpoints
// where the standard rule drifts.
TEST(AsaUniform, ProjectionRuleHasNoTangentialDrift) {
  Mesh m = asa_test::flat_grid(6);
  for (Vec3f& p : m.positions) p.x += 0.3f * std::sin(3.0f * p.y) * (p.x > 0 && p.x < 6);
  AsaOptions o = uniform(1);
  o.rule = ButterflyRule::kProjection;
  auto proj = subdivide(m, o);
  auto zorin = subdivide(m, uniform(1));
  ASSERT_TRUE(proj.has_value() && zorin.has_value());
  auto par = asa_test::parents(proj->mesh.triangles, m.vertex_count(), proj->mesh.vertex_count());
  float zorin_drift = 0;
  for (uint32_t i = 0; i < par.size(); ++i) {
    const Vec3f mid = (m.positions[par[i][0]] + m.positions[par[i][1]]) * 0.5f;
    const Vec3f p = proj->mesh.positions[m.vertex_count() + i];
    const Vec3f q = zorin->mesh.positions[m.vertex_count() + i];
    if (p.y > 0 && p.y < 6 && p.x > 0.5f && p.x < 5.5f) {
      EXPECT_LT(length(p - mid), 1e-5f);
    }
    zorin_drift = std::max(zorin_drift, length(q - mid));
  }
  EXPECT_GT(zorin_drift, 1e-3f);
  EXPECT_TRUE(asa_test::conforming(m, *proj));
}

TEST(AsaUniform, ZeroLevelsCopiesTheInput) {
  Mesh m = asa_test::octahedron();
  AsaOptions o = uniform(0);
  auto r = subdivide(m, o);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->mesh.triangles, m.triangles);
  EXPECT_EQ(r->mesh.positions, m.positions);
}

TEST(AsaUniform, BadInputAndOptionsAreErrors) {
  Mesh m = asa_test::octahedron();
  AsaOptions o = uniform(1);
  o.flatness = 2.0f;
  EXPECT_EQ(subdivide(m, o).error().code, ErrorCode::kInvalidArgument);
  o = uniform(-1);
  EXPECT_EQ(subdivide(m, o).error().code, ErrorCode::kInvalidArgument);
  o = uniform(1);
  o.crease_degrees = NAN;
  EXPECT_EQ(subdivide(m, o).error().code, ErrorCode::kInvalidArgument);
  Mesh bad = m;
  bad.triangles.push_back({0, 2, 4});  // edge used twice in the same direction
  EXPECT_EQ(subdivide(bad, uniform(1)).error().code, ErrorCode::kNonManifold);
  bad = m;
  bad.triangles[0][0] = 99;
  EXPECT_EQ(subdivide(bad, uniform(1)).error().code, ErrorCode::kInvalidMesh);
  bad = m;
  bad.positions[0].x = NAN;
  EXPECT_EQ(subdivide(bad, uniform(1)).error().code, ErrorCode::kInvalidMesh);
  o = uniform(8);
  EXPECT_EQ(subdivide(asa_test::flat_grid(200), o).error().code, ErrorCode::kLimit);
}

// Calls that reuse a workspace and a result give the same output as fresh ones.
TEST(AsaUniform, WorkspaceReuseGivesSameResult) {
  Mesh a = asa_test::icosahedron(),
       b = asa_test::grid(4, [](float x, float y) { return x * y * 0.1f; });
  AsaWorkspace ws;
  AsaResult result;
  for (int round = 0; round < 2; ++round) {
    for (const Mesh* m : {&a, &b}) {
      for (bool uni : {true, false}) {
        AsaOptions o;
        o.uniform = uni;
        o.levels = 2;
        o.flatness = 0.95f;
        ASSERT_TRUE(subdivide_into(*m, o, ws, result).has_value());
        auto fresh = subdivide(*m, o);
        EXPECT_EQ(result.mesh.positions, fresh->mesh.positions);
        EXPECT_EQ(result.mesh.triangles, fresh->mesh.triangles);
      }
    }
  }
}

}  // namespace
}  // namespace meshstream

namespace meshstream {
namespace {

TEST(AsaEdgeCases, EmptyMeshAndIsolatedVertices) {
  Mesh empty;
  auto r = subdivide(empty, AsaOptions{});
  ASSERT_TRUE(r.has_value());
  EXPECT_TRUE(r->mesh.empty());
  Mesh points;
  points.positions = {{0, 0, 0}, {1, 0, 0}};
  r = subdivide(points, AsaOptions{});
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->mesh.vertex_count(), 2u);
  // An isolated vertex next to a real mesh stays where it is.
  Mesh m = asa_test::octahedron();
  m.positions.push_back({5, 5, 5});
  AsaOptions o;
  o.uniform = true;
  r = subdivide(m, o);
  ASSERT_TRUE(r.has_value());
  EXPECT_TRUE(asa_test::conforming(m, *r));
}

// A double cone whose two apexes have valence 3000: weights are tabulated
// per valence present (O(K)), and the stencils stay finite.
TEST(AsaEdgeCases, HugeValence) {
  const uint32_t n = 3000;
  Mesh m;
  m.positions.push_back({0, 0, 1});
  m.positions.push_back({0, 0, -1});
  for (uint32_t i = 0; i < n; ++i) {
    const float a = 2.0f * 3.14159265f * i / n;
    m.positions.push_back({std::cos(a), std::sin(a), 0});
  }
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t a = 2 + i, b = 2 + (i + 1) % n;
    m.triangles.push_back({0, a, b});
    m.triangles.push_back({1, b, a});
  }
  AsaOptions o;
  o.uniform = true;
  o.levels = 2;
  auto r = subdivide(m, o);
  ASSERT_TRUE(r.has_value());
  EXPECT_TRUE(asa_test::conforming(m, *r));
}

}  // namespace
}  // namespace meshstream
