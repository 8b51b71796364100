// Incremental updates equal a full subdivision face for face, after records
// that move vertices and insert vertices (as the decoder's refinements do).
#include <random>

#include "common/asa/incremental.h"
#include "common/asa/view.h"
#include "common/mesh/procedural.h"
#include "tests/asa/asa_test_support.h"

namespace meshstream {
namespace {

using asa_test::insert_vertex;
using asa_test::same_output;

void run_records(const Mesh& start, const AsaOptions& options, int records, const char* what,
                 bool expect_partial = true) {
  IncrementalSubdivider inc(options);
  ASSERT_TRUE(inc.update(start).has_value());
  EXPECT_TRUE(inc.last_update().full);
  Mesh m = start;
  std::mt19937 rng(7);
  int partial = 0;
  for (int r = 0; r < records; ++r) {
    if (r % 3 == 2) {
      const uint32_t v = rng() % m.vertex_count();
      m.positions[v] = m.positions[v] * 1.01f;  // a moved vertex
    } else {
      insert_vertex(m, rng() % m.face_count(), (r % 2 ? 0.2f : -0.1f));
    }
    ASSERT_TRUE(inc.update(m).has_value()) << what;
    partial += !inc.last_update().full;
    auto full = subdivide(m, options);
    ASSERT_TRUE(full.has_value());
    EXPECT_TRUE(asa_test::same_incremental(inc, *full)) << what << " after record " << r;
    EXPECT_TRUE(asa_test::conforming_incremental(m, inc)) << what << " after record " << r;
  }
  if (expect_partial) {
    EXPECT_GT(partial, records / 2) << what << ": most updates should be partial";
  }
}

TEST(AsaIncremental, UniformMatchesFullSubdivision) {
  AsaOptions o;
  o.uniform = true;
  o.levels = 2;
  run_records(asa_test::icosahedron(), o, 4, "icosahedron", false);  // tiny: full updates
  MESHSTREAM_REQUIRE_TEST_MESHES();
  run_records(asa_test::load("sphere_low.off"), o, 12, "sphere_low uniform");
  o.levels = 3;
  run_records(asa_test::load("hemisphere.off"), o, 8, "hemisphere uniform L3");
}

TEST(AsaIncremental, AdaptiveAndCreasesMatchFullSubdivision) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  AsaOptions o;
  o.levels = 2;
  o.flatness = 0.8f;
  run_records(asa_test::load("fandisk.off"), o, 12, "fandisk ASA");
  o.crease_degrees = 45;
  run_records(asa_test::load("fandisk.off"), o, 8, "fandisk ASA crease");
  o = {};
  o.levels = 3;
  o.flatness = 0.9f;
  run_records(asa_test::load("bunny.off"), o, 6, "bunny ASA L3");
}

// A batch of records too large for a region (many merged updates) falls
// back to a full run that keeps the live level-0 adjacency instead of
// rebuilding it; the single records after it are partial again, and every
// result equals a full run, with and without a camera.
TEST(AsaIncremental, BatchesTooLargeForARegionStayExact) {
  const Mesh start = make_demo_mesh(8000);
  for (bool camera : {false, true}) {
    AsaOptions o;
    o.levels = 2;
    if (camera) {
      o.view.enabled = true;
      o.view.camera = fit_camera(start, 320, 240);
      o.view.facing_sign = facing_sign_of(start);
    }
    IncrementalSubdivider inc(o);
    ASSERT_TRUE(inc.update(start).has_value());
    Mesh m = start;
    std::mt19937 rng(3);
    int partial_after_batch = 0;
    for (int round = 0; round < 3; ++round) {
      for (int i = 0; i < 600; ++i) insert_vertex(m, rng() % m.face_count(), 0.15f);
      ASSERT_TRUE(inc.update(m).has_value());
      EXPECT_GT(inc.last_update().dirty_faces, m.face_count() / 4) << "the batch fit a region";
      EXPECT_TRUE(asa_test::same_incremental(inc, *subdivide(m, o)))
          << camera << " batch " << round;
      for (int r = 0; r < 3; ++r) {
        insert_vertex(m, rng() % m.face_count(), r % 2 ? 0.2f : -0.1f);
        ASSERT_TRUE(inc.update(m).has_value());
        partial_after_batch += !inc.last_update().full && inc.last_update().dirty_faces > 0 &&
                               inc.last_update().dirty_faces < m.face_count() / 4;
        EXPECT_TRUE(asa_test::same_incremental(inc, *subdivide(m, o)))
            << camera << " batch " << round << " record " << r;
      }
    }
    EXPECT_GT(partial_after_batch, 4) << camera;
  }
}

TEST(AsaIncremental, ColorsFollowAndNothingChangedIsFree) {
  Mesh m = asa_test::grid(20, [](float x, float y) { return 0.3f * std::sin(x) * std::cos(y); });
  for (uint32_t v = 0; v < m.vertex_count(); ++v) m.colors.push_back({v / 441.0f, 0, 1, 1});
  AsaOptions o;
  o.levels = 2;
  o.flatness = 0.95f;
  IncrementalSubdivider inc(o);
  ASSERT_TRUE(inc.update(m).has_value());
  ASSERT_TRUE(inc.update(m).has_value());
  EXPECT_FALSE(inc.last_update().full);
  EXPECT_EQ(inc.last_update().changed_vertices, 0u);
  insert_vertex(m, 300, 0.3f);
  ASSERT_TRUE(inc.update(m).has_value());
  auto full = subdivide(m, o);
  EXPECT_TRUE(asa_test::same_incremental(inc, *full));
  ASSERT_EQ(inc.result().mesh.colors.size(), inc.result().mesh.positions.size());
  // Bad input after good: an error, and the next good update is full.
  Mesh bad = m;
  bad.positions[0].x = NAN;
  EXPECT_FALSE(inc.update(bad).has_value());
  ASSERT_TRUE(inc.update(m).has_value());
  EXPECT_TRUE(inc.last_update().full);
}

}  // namespace
}  // namespace meshstream
