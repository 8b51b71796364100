// The incremental subdivider's in-place splice and its copies: after random
// sequences of camera moves and records, the result kept in place equals a
// full run at the same camera and mesh (face for face in canonical order,
// the same set of triangles in place), stays conforming, and copies brought
// up to date by copy_result_into equal it array for array while copying only
// the changes.
#include <cstdio>
#include <random>

#include "common/asa/incremental.h"
#include "common/asa/view.h"
#include "common/mesh/procedural.h"
#include "tests/asa/asa_test_support.h"

namespace meshstream {
namespace {

using asa_test::insert_vertex;

struct Copy {
  Mesh mesh;
  std::vector<FaceKind> kinds;
  uint64_t version = 0;
  // Since it was last brought up to date: a rebuilt result, updates.
  bool rebuilt_since = true;
  size_t updates_since = 0;
  // True when the copy had to be copied whole though only changes were due.
  bool refresh(const IncrementalSubdivider& inc) {
    const bool only_changes = inc.copy_result_into(mesh, kinds, version);
    const bool due = !rebuilt_since && updates_since <= IncrementalSubdivider::kLoggedChanges;
    rebuilt_since = false;
    updates_since = 0;
    return due && !only_changes;
  }
  void after_update(const IncrementalSubdivider& inc) {
    rebuilt_since = rebuilt_since || inc.last_update().rebuilt;
    ++updates_since;
  }
};

// `steps` random steps: a camera move (orbit, zoom, sometimes a new
// tolerance), a record (a vertex inserted or moved) or both; after each,
// the in-place result against a full run, and one of three copies (as the
// display pool's) brought up to date and compared array for array.
void check_random_sequence(const Mesh& start, const std::string& name, int levels, int steps,
                           int width, int height) {
  const AsaCamera fit = fit_camera(start, width, height);
  AsaOptions o;
  o.levels = levels;
  o.view.enabled = true;
  o.view.camera = fit;
  o.view.pixel_tolerance = 2;
  o.view.facing_sign = facing_sign_of(start);
  IncrementalSubdivider inc(o);
  ASSERT_TRUE(inc.update(start).has_value());
  Mesh m = start;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(0, 1);
  const Vec3f offset = fit.eye - fit.target;
  float angle = 0, zoom = 1;
  Copy copies[3];
  int partial = 0, whole_after_region = 0;
  for (int step = 0; step < steps; ++step) {
    const uint32_t kind = rng() % 3;  // 0 camera, 1 record, 2 both
    if (kind != 1) {
      angle += 0.02f + 0.2f * unit(rng);
      zoom = std::clamp(zoom * (0.8f + 0.4f * unit(rng)), 0.25f, 1.2f);
      AsaView view = o.view;
      const Vec3f turned{offset.x * std::cos(angle) - offset.z * std::sin(angle), offset.y,
                         offset.x * std::sin(angle) + offset.z * std::cos(angle)};
      view.camera.eye = fit.target + turned * zoom;
      if (rng() % 5 == 0) view.pixel_tolerance = 1.0f + static_cast<float>(rng() % 3);
      o.view = view;
      inc.set_view(view);
    }
    if (kind != 0) {
      if (rng() % 3 == 0) {
        const uint32_t v = rng() % m.vertex_count();
        m.positions[v] = m.positions[v] * 1.002f;
      } else {
        insert_vertex(m, rng() % m.face_count(), unit(rng) < 0.5f ? 0.2f : -0.1f);
      }
    }
    ASSERT_TRUE(inc.update(m).has_value()) << name << " step " << step;
    const bool region = !inc.last_update().full;
    partial += region;
    for (Copy& c : copies) c.after_update(inc);
    auto full = subdivide(m, o);
    ASSERT_TRUE(full.has_value());
    ASSERT_TRUE(asa_test::same_incremental(inc, *full)) << name << " step " << step;
    ASSERT_TRUE(asa_test::conforming_incremental(m, inc)) << name << " step " << step;
    Copy& copy = copies[rng() % 3];
    whole_after_region += copy.refresh(inc);
    const Mesh& r = inc.result().mesh;
    ASSERT_EQ(copy.version, inc.version());
    ASSERT_TRUE(copy.mesh.triangles == r.triangles) << name << " step " << step;
    ASSERT_EQ(copy.kinds, inc.result().face_kind) << name << " step " << step;
    ASSERT_EQ(copy.mesh.positions.size(), r.positions.size());
    ASSERT_EQ(std::memcmp(copy.mesh.positions.data(), r.positions.data(),
                          sizeof(Vec3f) * r.positions.size()),
              0)
        << name << " step " << step;
  }
  // Some steps took the region path; a copy no rebuilt result made stale
  // (and at most kLoggedChanges updates behind) copied only the changes.
  std::printf("%s: %d of %d steps region updates\n", name.c_str(), partial, steps);
  EXPECT_GT(partial, steps / 4) << name;
  EXPECT_EQ(whole_after_region, 0) << name;
}

TEST(AsaInPlace, RandomCameraMovesAndRecordsEqualFullRunsProcedural) {
  // Finer than the screen (40k faces on 160 x 120), as a big model is.
  check_random_sequence(make_demo_mesh(40000), "demo L1", 1, 40, 160, 120);
  check_random_sequence(make_demo_mesh(20000), "demo L2", 2, 20, 160, 120);
}

TEST(AsaInPlace, RandomCameraMovesAndRecordsEqualFullRunsRealMeshes) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  check_random_sequence(asa_test::load("bunny.off"), "bunny.off", 1, 30, 320, 240);
  check_random_sequence(asa_test::load("dragon_res3.ply"), "dragon_res3.ply", 2, 15, 320, 240);
}

// Many records that each add vertices: the input outgrows its vertex slots
// (renumbering, a whole copy) and the result stays exact; the unused slots
// stay within the bound.
TEST(AsaInPlace, GrowingInputStaysExactPastItsSlots) {
  Mesh m = make_demo_mesh(3000);
  AsaOptions o;
  o.levels = 1;
  o.flatness = 0.9f;
  IncrementalSubdivider inc(o);
  ASSERT_TRUE(inc.update(m).has_value());
  const uint32_t slots = inc.input_slots();
  std::mt19937 rng(2);
  Copy copy;
  int region = 0, whole_after_region = 0, renumbered = 0;
  for (int r = 0; r < 120; ++r) {
    for (int i = 0; i < 12; ++i) insert_vertex(m, rng() % m.face_count(), 0.1f);
    ASSERT_TRUE(inc.update(m).has_value());
    copy.after_update(inc);
    region += !inc.last_update().full;
    renumbered += inc.last_update().rebuilt;
    whole_after_region += copy.refresh(inc);
    ASSERT_TRUE(copy.mesh.triangles == inc.result().mesh.triangles) << "record " << r;
    if (r % 10 == 9) {
      ASSERT_TRUE(asa_test::same_incremental(inc, *subdivide(m, o))) << "record " << r;
      ASSERT_TRUE(asa_test::conforming_incremental(m, inc)) << "record " << r;
    }
  }
  EXPECT_GT(m.vertex_count(), slots) << "the input should outgrow its first slots";
  EXPECT_GT(inc.input_slots(), slots);
  std::printf("%d of 120 region updates, %d rebuilt\n", region, renumbered);
  EXPECT_GT(region, 60);
  EXPECT_EQ(whole_after_region, 0);
  EXPECT_LT(renumbered, 120 - region + 6) << "renumbering should be rare";
}

}  // namespace
}  // namespace meshstream
