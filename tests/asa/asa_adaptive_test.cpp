// ASA on real meshes: conforming output at every t and level, sizes that
// fall as t decreases, and the two ends of t (everything / nothing).
#include "tests/asa/asa_test_support.h"

namespace meshstream {
namespace {

AsaOptions asa(int levels, float t) {
  AsaOptions o;
  o.levels = levels;
  o.flatness = t;
  return o;
}

TEST(AsaAdaptive, RealMeshesStayConformingManifolds) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  for (auto [name, levels] :
       {std::pair{"fandisk.off", 3}, std::pair{"hemisphere.off", 3}, std::pair{"mask.off", 2},
        std::pair{"bunny.off", 2}, std::pair{"casting.off", 3}}) {
    Mesh m = asa_test::load(name);
    // hemisphere's finest dihedral angles are below 18 degrees: only t very
    // close to 1 refines it.
    for (float t : {0.999f, 0.9f, 0.8f}) {
      auto r = subdivide(m, asa(levels, t));
      ASSERT_TRUE(r.has_value()) << name;
      EXPECT_TRUE(asa_test::conforming(m, *r)) << name << " t=" << t;
      if (t > 0.99f) {
        EXPECT_GT(r->mesh.face_count(), m.face_count()) << name;
      }
      int bisected = 0;
      for (FaceKind k : r->face_kind) bisected += k == FaceKind::kBisected;
      EXPECT_EQ(bisected % 2, 0) << "bisected faces come in pairs";
    }
  }
}

TEST(AsaAdaptive, SizesFallMonotonicallyAsTDecreases) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  for (const char* name : {"bunny.off", "fandisk.off", "sphere_low.off"}) {
    Mesh m = asa_test::load(name);
    AsaOptions u;
    u.uniform = true;
    u.levels = 2;
    uint32_t previous = subdivide(m, u)->mesh.vertex_count();
    for (float t : {0.99f, 0.95f, 0.9f, 0.8f, 0.7f, 0.5f, 0.0f}) {
      auto r = subdivide(m, asa(2, t));
      ASSERT_TRUE(r.has_value());
      EXPECT_LE(r->mesh.vertex_count(), previous) << name << " t=" << t;
      previous = r->mesh.vertex_count();
    }
  }
}

// t = 1 targets every face whose neighbours are not exactly coplanar: on a
// sphere that is all of them, and ASA then equals the uniform scheme bit for
// bit (same vertex and face order).
TEST(AsaAdaptive, TOneIsUniformAndTMinusOneChangesNothing) {
  Mesh m = asa_test::icosahedron();
  AsaOptions u;
  u.uniform = true;
  u.levels = 2;
  auto uniform = subdivide(m, u);
  auto all = subdivide(m, asa(2, 1.0f));
  ASSERT_TRUE(uniform.has_value() && all.has_value());
  EXPECT_EQ(all->mesh.positions, uniform->mesh.positions);
  EXPECT_EQ(all->mesh.triangles, uniform->mesh.triangles);
  auto none = subdivide(m, asa(2, -1.0f));
  ASSERT_TRUE(none.has_value());
  EXPECT_EQ(none->mesh.triangles, m.triangles);
  for (FaceKind k : none->face_kind) EXPECT_EQ(k, FaceKind::kUntouched);
}

// Flat regions are left alone: a plane with one bump refines only around it.
TEST(AsaAdaptive, FlatRegionsAreNotRefined) {
  Mesh m = asa_test::grid(12, [](float x, float y) {
    const float d2 = (x - 6) * (x - 6) + (y - 6) * (y - 6);
    return d2 < 4 ? 2.0f * (1 - d2 / 4) : 0.0f;
  });
  auto r = subdivide(m, asa(3, 0.9f));
  ASSERT_TRUE(r.has_value());
  EXPECT_TRUE(asa_test::conforming(m, *r));
  // Faces far from the bump stay untouched.
  int far_untouched = 0;
  for (uint32_t f = 0; f < r->mesh.face_count(); ++f) {
    const Triangle& t = r->mesh.triangles[f];
    const Vec3f c =
        (r->mesh.positions[t[0]] + r->mesh.positions[t[1]] + r->mesh.positions[t[2]]) / 3.0f;
    if (std::abs(c.x - 6) > 4.5f || std::abs(c.y - 6) > 4.5f) {
      EXPECT_EQ(r->face_kind[f], FaceKind::kUntouched);
      ++far_untouched;
    }
  }
  EXPECT_GT(far_untouched, 100);
  AsaOptions u;
  u.uniform = true;
  u.levels = 3;
  EXPECT_LT(r->mesh.face_count(), subdivide(m, u)->mesh.face_count() / 4);
}

}  // namespace
}  // namespace meshstream
