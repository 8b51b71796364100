// The renderer's cull (common/asa/display_cull.h) does not change the
// picture: the culled mesh and the whole one, drawn by the viewer's renderer
// with the same camera and planes, give the same pixels, from outside
// closed models, from behind open surfaces (whose back faces the renderer
// shows), zoomed in (most faces off screen) and from a camera that moved
// within the cull's region (the viewer draws a cull made for an older camera).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "client/viewer/image_psnr.h"
#include "client/viewer/offscreen.h"
#include "common/asa/display_cull.h"
#include "common/mesh/import.h"
#include "common/mesh/procedural.h"
#include "tests/test_meshes.h"

namespace meshstream::client {
namespace {

RgbaImage picture(const Mesh& mesh, const Mesh& whole, const AsaCamera& camera) {
  OffscreenRequest r;
  r.width = camera.width;
  r.height = camera.height;
  r.camera = camera;
  r.frame_on = &whole;  // the planes of the whole mesh, as the client draws a cull
  auto image = render_offscreen(mesh, r);
  EXPECT_TRUE(image) << (image ? "" : image.error().message);
  return image ? *image : RgbaImage{};
}

// Culls `mesh` for `cull_camera`, draws both at `draw_camera` (inside the
// region), and returns the share of faces left out.
double expect_same_picture(const Mesh& mesh, const AsaCamera& cull_camera,
                           const AsaCamera& draw_camera, const std::string& what) {
  auto whole = std::make_shared<const Mesh>(mesh);
  const auto topology = analyze_display_topology(mesh);
  const CulledDisplay c = cull_display(whole, nullptr, *topology, cull_camera);
  EXPECT_TRUE(cull_valid_for(c.region, draw_camera, 0)) << what;
  const RgbaImage a = picture(*whole, *whole, draw_camera);
  const RgbaImage b = picture(*c.mesh, *whole, draw_camera);
  const double db = psnr_rgb(a, b);
  if (std::getenv("MESHSTREAM_CULL_TEST_VERBOSE")) std::printf("%s: %.1f dB\n", what.c_str(), db);
  EXPECT_GT(db, 60.0) << what << ": " << c.mesh->face_count() << " of " << mesh.face_count()
                      << " faces";
  return 1.0 - double(c.mesh->face_count()) / double(mesh.face_count());
}

AsaCamera turned(const AsaCamera& c, float degrees) {
  const float a = degrees * 3.14159265f / 180.0f;
  const Vec3f o = c.eye - c.target;
  AsaCamera t = c;
  t.eye = c.target +
          Vec3f{o.x * std::cos(a) - o.z * std::sin(a), o.y, o.x * std::sin(a) + o.z * std::cos(a)};
  return t;
}

TEST(DisplayCullPicture, ClosedModelsFromOutside) {
  const Mesh demo = make_demo_mesh(4000);
  const AsaCamera camera = fit_camera(demo, 200, 150);
  EXPECT_GT(expect_same_picture(demo, camera, camera, "demo"), 0.25);
  EXPECT_GT(expect_same_picture(demo, camera, turned(camera, 0.4f), "demo, turned 0.4 degrees"),
            0.25);
  auto bunny = import_mesh(testing::test_mesh("bunny.off"));  // closed scan
  ASSERT_TRUE(bunny);
  const AsaCamera bc = fit_camera(bunny->mesh, 200, 150);
  EXPECT_GT(expect_same_picture(bunny->mesh, bc, bc, "bunny.off"), 0.25);
}

TEST(DisplayCullPicture, OpenSurfacesFromBehind) {
  for (const char* name : {"hemisphere.off", "mask.off"}) {
    auto m = import_mesh(testing::test_mesh(name));
    ASSERT_TRUE(m) << name;
    for (float degrees : {0.0f, 180.0f}) {
      const AsaCamera camera = turned(fit_camera(m->mesh, 200, 150), degrees);
      expect_same_picture(m->mesh, camera, camera,
                          std::string(name) + " turned " + std::to_string(int(degrees)));
    }
  }
}

// Looking into a sphere through a hole around its pole: the inside shows.
TEST(DisplayCullPicture, ThroughAHole) {
  const Mesh sphere = make_icosphere(4);
  Mesh holed;
  holed.positions = sphere.positions;
  for (const Triangle& t : sphere.triangles) {
    const Vec3f c =
        (sphere.positions[t[0]] + sphere.positions[t[1]] + sphere.positions[t[2]]) / 3.0f;
    if (c.z < 0.8f) holed.triangles.push_back(t);
  }
  for (const Vec3f eye : {Vec3f{0, 0, 5}, Vec3f{0.8f, 0.3f, 4}}) {
    AsaCamera camera;
    camera.eye = eye;
    camera.target = {0, 0, 0};
    camera.width = 200;
    camera.height = 150;
    expect_same_picture(holed, camera, camera, "holed sphere");
  }
}

TEST(DisplayCullPicture, ZoomedIn) {
  const Mesh demo = make_demo_mesh(4000);
  AsaCamera camera = fit_camera(demo, 200, 150);
  camera.eye = camera.target + (camera.eye - camera.target) * 0.3f;
  camera.fov_degrees = 12;
  EXPECT_GT(expect_same_picture(demo, camera, camera, "demo zoomed in"), 0.5);
}

}  // namespace
}  // namespace meshstream::client
