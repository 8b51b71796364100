// View-dependent ASA (common/asa/view.h): with a camera that sees every
// edge large, the same output as whole-mesh ASA; for any camera a
// conforming mesh, never more faces than without a camera, within the
// display budget; incremental camera moves equal full runs.
#include <random>

#include "common/asa/display_budget.h"
#include "common/asa/incremental.h"
#include "common/asa/view.h"
#include "tests/asa/asa_test_support.h"

namespace meshstream {
namespace {

using asa_test::conforming;
using asa_test::same_output;

// An open height field of strong bumps, all faces towards +z.
Mesh bumpy_grid(int n) {
  return asa_test::grid(
      n, [](float x, float y) { return 2.0f * std::sin(0.7f * x) * std::cos(0.6f * y); });
}

AsaOptions with_view(int levels, const AsaCamera& camera, float tolerance) {
  AsaOptions o;
  o.levels = levels;
  o.view.enabled = true;
  o.view.camera = camera;
  o.view.pixel_tolerance = tolerance;
  return o;
}

AsaResult run(const Mesh& mesh, const AsaOptions& options) {
  auto r = subdivide(mesh, options);
  EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message);
  return r ? std::move(*r) : AsaResult{};
}

// A camera that sees the whole model with every edge far above the
// tolerance makes no difference: face for face the view-independent result.
TEST(AsaView, CameraSeeingEverythingEqualsViewIndependent) {
  const Mesh grid = bumpy_grid(24);
  AsaCamera above;
  above.eye = {12, 12, 60};
  above.target = {12, 12, 0};
  for (int levels : {1, 2, 3}) {
    AsaOptions plain;
    plain.levels = levels;
    const AsaResult expected = run(grid, plain);
    ASSERT_GT(expected.mesh.face_count(), grid.face_count());
    EXPECT_TRUE(same_output(run(grid, with_view(levels, above, 1e-4f)), expected))
        << levels << " levels";
  }
  // Closed models: every face is seen only without back-face culling.
  for (const Mesh& closed : {make_demo_mesh(6000), make_torus(24, 12)}) {
    AsaOptions plain;
    plain.levels = 2;
    AsaOptions viewed = with_view(2, fit_camera(closed, 640, 480), 1e-4f);
    viewed.view.cull_back_faces = false;
    EXPECT_TRUE(same_output(run(closed, viewed), run(closed, plain)));
  }
}

TEST(AsaView, RealMeshesSeenWholeEqualViewIndependent) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  for (const char* name : {"bunny.off", "fandisk.off", "hemisphere.off"}) {
    const Mesh mesh = asa_test::load(name);
    AsaOptions plain;
    plain.levels = 2;
    AsaOptions viewed = with_view(2, fit_camera(mesh, 800, 600), 1e-5f);
    viewed.view.cull_back_faces = false;
    EXPECT_TRUE(same_output(run(mesh, viewed), run(mesh, plain))) << name;
  }
}

// What the screen cannot show is not refined: a camera looking away, one so
// far that the model is a few pixels, or a coarse tolerance add nothing.
TEST(AsaView, InvisibleOrTinyAddsNothing) {
  const Mesh mesh = make_demo_mesh(6000);
  const AsaCamera fit = fit_camera(mesh, 640, 480);
  AsaCamera away = fit;
  away.target = fit.eye + (fit.eye - fit.target);  // looks the other way
  AsaCamera far = fit;
  far.eye = fit.target + (fit.eye - fit.target) * 1000.0f;
  for (const AsaCamera& camera : {away, far}) {
    const AsaResult r = run(mesh, with_view(3, camera, 2));
    EXPECT_EQ(r.mesh.face_count(), mesh.face_count());
  }
  EXPECT_EQ(run(mesh, with_view(3, fit, 1e6f)).mesh.face_count(), mesh.face_count());
  // The real camera refines, but less than the whole mesh (back faces).
  AsaOptions plain;
  plain.levels = 2;
  const uint32_t everything = run(mesh, plain).mesh.face_count();
  const uint32_t viewed = run(mesh, with_view(2, fit, 0.5f)).mesh.face_count();
  EXPECT_GT(viewed, mesh.face_count());
  EXPECT_LT(viewed, everything);
}

// Random cameras around, inside and near the model.
AsaCamera random_camera(const Mesh& mesh, std::mt19937& rng) {
  const BoundingBox box = bounding_box(mesh);
  const Vec3f centre = (box.min + box.max) * 0.5f;
  const float radius = box.diagonal() / 2;
  std::uniform_real_distribution<float> unit(-1, 1), dist(0.2f, 4.0f), fov(15, 100);
  Vec3f dir{unit(rng), unit(rng), unit(rng)};
  if (length(dir) < 1e-3f) dir = {0, 0, 1};
  AsaCamera c;
  c.eye = centre + normalized(dir) * (radius * dist(rng));
  c.target = centre + Vec3f{unit(rng), unit(rng), unit(rng)} * (0.3f * radius);
  c.fov_degrees = fov(rng);
  c.width = 320 + static_cast<int>(rng() % 1000);
  c.height = 240 + static_cast<int>(rng() % 700);
  return c;
}

void check_random_cameras(const Mesh& mesh, const std::string& name, int cameras) {
  std::mt19937 rng(11);
  AsaOptions plain;
  plain.levels = 2;
  const uint32_t everything = run(mesh, plain).mesh.face_count();
  AsaWorkspace ws;
  for (int i = 0; i < cameras; ++i) {
    AsaOptions o = with_view(2, random_camera(mesh, rng), 0.5f + 0.5f * (rng() % 8));
    o.view.facing_sign = facing_sign_of(mesh);
    AsaResult r;
    ASSERT_TRUE(subdivide_into(mesh, o, ws, r).has_value());
    const std::string what = name + " camera " + format_camera(o.view.camera);
    EXPECT_TRUE(conforming(mesh, r)) << what;
    EXPECT_LE(r.mesh.face_count(), everything) << what;
    // The budget is never exceeded, whatever it is.
    const uint64_t budget = mesh.face_count() + (r.mesh.face_count() - mesh.face_count()) / 3 + 1;
    BudgetOutcome outcome;
    AsaResult limited;
    ASSERT_TRUE(subdivide_within_budget(mesh, o, budget, ws, limited, outcome).has_value());
    EXPECT_LE(limited.mesh.face_count(), budget) << what;
    EXPECT_TRUE(conforming(mesh, limited)) << what;
    if (r.mesh.face_count() > budget) {
      EXPECT_TRUE(outcome.limited) << what;
      EXPECT_GE(outcome.pixel_tolerance, o.view.pixel_tolerance) << what;
    }
  }
}

TEST(AsaView, RandomCamerasConformAndKeepTheBudgetProcedural) {
  check_random_cameras(make_demo_mesh(8000), "demo", 12);
  check_random_cameras(bumpy_grid(40), "grid", 12);
  check_random_cameras(make_torus(40, 20), "torus", 8);
}

TEST(AsaView, RandomCamerasConformAndKeepTheBudgetRealMeshes) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  for (const char* name : {"bunny.off", "fandisk.off", "hemisphere.off", "mask.off", "skull.obj"})
    check_random_cameras(asa_test::load(name), name, 6);
}

// A budget below the input keeps the input; one below the whole-mesh
// result raises the tolerance and says so.
TEST(AsaView, BudgetRaisesTheTolerance) {
  const Mesh mesh = make_demo_mesh(6000);
  AsaOptions o = with_view(3, fit_camera(mesh, 1280, 720), 0.25f);
  AsaWorkspace ws;
  AsaResult free_run, limited;
  BudgetOutcome outcome;
  ASSERT_TRUE(subdivide_within_budget(mesh, o, 0, ws, free_run, outcome).has_value());
  EXPECT_FALSE(outcome.limited);
  const uint64_t budget = (mesh.face_count() + free_run.mesh.face_count()) / 2;
  ASSERT_TRUE(subdivide_within_budget(mesh, o, budget, ws, limited, outcome).has_value());
  EXPECT_TRUE(outcome.limited);
  EXPECT_GT(outcome.pixel_tolerance, 0.25f);
  EXPECT_LE(limited.mesh.face_count(), budget);
  EXPECT_GT(limited.mesh.face_count(), mesh.face_count());
  ASSERT_TRUE(
      subdivide_within_budget(mesh, o, mesh.face_count() - 1, ws, limited, outcome).has_value());
  EXPECT_EQ(limited.mesh.face_count(), mesh.face_count());
  EXPECT_EQ(outcome.levels, 0);
}

// Orbit, zoom and pan steps, with records in between: each incremental
// result equals a full run at the new camera; camera moves over a model
// finer than the screen redo only part of it.
void check_camera_moves(const Mesh& start, const std::string& name, bool expect_partial,
                        int width = 800, int height = 600) {
  const AsaCamera fit = fit_camera(start, width, height);
  AsaOptions o = with_view(2, fit, 2);
  o.view.facing_sign = facing_sign_of(start);
  IncrementalSubdivider inc(o);
  ASSERT_TRUE(inc.update(start).has_value());
  // The first update subdivides only what the screen may refine, when that
  // is a small region: the same as a full run.
  EXPECT_TRUE(asa_test::same_incremental(inc, run(start, o))) << name << " first update";
  Mesh m = start;
  std::mt19937 rng(5);
  int partial = 0;
  const Vec3f offset = fit.eye - fit.target;
  for (int step = 0; step < 10; ++step) {
    AsaView view = o.view;
    const float angle = 0.15f * static_cast<float>(step);
    const float zoom = step < 5 ? 1.0f - 0.15f * static_cast<float>(step) : 0.3f;
    const Vec3f turned{offset.x * std::cos(angle) - offset.z * std::sin(angle), offset.y,
                       offset.x * std::sin(angle) + offset.z * std::cos(angle)};
    view.camera.eye = fit.target + turned * zoom;
    if (step % 3 == 2) view.pixel_tolerance = 1.0f + static_cast<float>(step % 4);
    inc.set_view(view);
    if (step % 4 == 3) {
      const uint32_t v = rng() % m.vertex_count();
      m.positions[v] = m.positions[v] * 1.01f;  // and a record moved a vertex
    }
    ASSERT_TRUE(inc.update(m).has_value());
    partial += !inc.last_update().full;
    AsaOptions full_options = o;
    full_options.view = view;
    const AsaResult full = run(m, full_options);
    EXPECT_TRUE(asa_test::same_incremental(inc, full)) << name << " step " << step;
    EXPECT_TRUE(asa_test::conforming_incremental(m, inc)) << name << " step " << step;
  }
  if (expect_partial) {
    EXPECT_GT(partial, 0) << name << ": some camera moves should be partial";
  }
}

TEST(AsaView, IncrementalCameraMovesEqualFullRuns) {
  // 40k faces on a 200 x 150 image: finer than the screen, as a big model
  // on a real window, so most of it stays quiet as the camera moves.
  check_camera_moves(make_demo_mesh(40000), "demo", true, 120, 90);
  check_camera_moves(bumpy_grid(60), "grid", false);
}

TEST(AsaView, IncrementalCameraMovesEqualFullRunsRealMeshes) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  for (const char* name : {"bunny.off", "fandisk.off", "skull.obj"})
    check_camera_moves(asa_test::load(name), name, false);
}

TEST(AsaView, CameraTextIsCheckedAndNamed) {
  AsaCamera c;
  ASSERT_TRUE(parse_camera("1,2,3,0,0,0", c).has_value());
  EXPECT_EQ(c.eye, (Vec3f{1, 2, 3}));
  EXPECT_EQ(c.fov_degrees, 45.0f);
  ASSERT_TRUE(parse_camera("1,2,3,0,0,0,30.5", c).has_value());
  EXPECT_EQ(c.fov_degrees, 30.5f);
  for (const char* bad : {"1,2,3,0,0", "1,2,3,0,0,0,45,1", "1,2,x,0,0,0", "1,1,1,1,1,1",
                          "1,2,3,0,0,0,180", "1,2,3,0,0,0,0", "1,2,3,0,0,0,-5", "", "1,2,3,,0,0"}) {
    auto r = parse_camera(bad, c);
    ASSERT_FALSE(r.has_value()) << bad;
    EXPECT_NE(r.error().message.find(std::string("--camera ") + bad), std::string::npos)
        << r.error().message;
  }
  AsaOptions o;
  o.view.enabled = true;
  o.view.pixel_tolerance = 0;
  EXPECT_FALSE(subdivide(make_icosahedron(), o).has_value());
}

// The snapshot camera frames the model like the viewer: every vertex on
// screen.
TEST(AsaView, FitCameraSeesEveryVertex) {
  const Mesh mesh = make_torus();
  const AsaCamera c = fit_camera(mesh, 1280, 720);
  const Vec3f f = normalized(c.target - c.eye);
  const Vec3f r = normalized(cross(f, Vec3f{0, 1, 0})), u = cross(r, f);
  const float t = std::tan(c.fov_degrees * 3.14159265f / 360.0f);
  for (const Vec3f& p : mesh.positions) {
    const Vec3f rel = p - c.eye;
    const float z = dot(rel, f);
    ASSERT_GT(z, 0);
    EXPECT_LE(std::fabs(dot(rel, u)) / z, t);
    EXPECT_LE(std::fabs(dot(rel, r)) / z, t * 1280.0f / 720.0f);
  }
}

}  // namespace
}  // namespace meshstream
