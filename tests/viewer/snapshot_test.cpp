// Off-screen snapshots (OSMesa): not blank, the whole model framed, and
// different where the input differs (mesh resolution, colour mode).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "client/viewer/offscreen.h"
#include "client/viewer/viewer.h"
#include "common/asa/subdivide.h"
#include "common/mesh/procedural.h"
#include "tests/viewer/image_checks.h"

namespace meshstream::client {
namespace {

using testing::differing_pixels;
using testing::foreground_coverage;

OffscreenRequest small_request() {
  OffscreenRequest request;
  request.width = 320;
  request.height = 240;
  return request;
}

RgbaImage render_or_fail(const Mesh& mesh, const OffscreenRequest& request) {
  auto image = render_offscreen(mesh, request);
  EXPECT_TRUE(image.has_value()) << (image ? "" : image.error().message);
  if (!image) return RgbaImage{};
  static int counter = 0;
  testing::keep_for_inspection(
      *image, std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
                  std::to_string(counter++));
  return *image;
}

std::string temp_png(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("meshstream_viewer_" + name + ".png")).string();
}

TEST(Snapshot, DemoModelIsFramedAndNotBlank) {
  Mesh mesh = make_demo_mesh(20000);
  RgbaImage image = render_or_fail(mesh, small_request());
  ASSERT_EQ(image.width, 320);
  ASSERT_EQ(image.height, 240);
  auto c = foreground_coverage(image);
  // Not blank: the model covers a good part of the picture.
  EXPECT_GT(c.foreground, 320u * 240u / 8);
  // Framed: no part is cut off at an edge...
  EXPECT_GT(c.min_x, 0);
  EXPECT_GT(c.min_y, 0);
  EXPECT_LT(c.max_x, image.width - 1);
  EXPECT_LT(c.max_y, image.height - 1);
  // ...and it is not lost in the middle: it spans most of the smaller side.
  int span = std::max(c.max_x - c.min_x + 1, c.max_y - c.min_y + 1);
  EXPECT_GT(span, image.height * 7 / 10) << "spans " << span << " px";
}

TEST(Snapshot, FramesModelsOfAnyScaleAndPlace) {
  // The same sphere, tiny and far from the origin, must look the same.
  Mesh unit = make_icosphere(3);
  Mesh moved = unit;
  for (Vec3f& p : moved.positions) p = p * 1e-3f + Vec3f{250.0f, -40.0f, 7.0f};
  RgbaImage a = render_or_fail(unit, small_request());
  RgbaImage b = render_or_fail(moved, small_request());
  auto ca = foreground_coverage(a), cb = foreground_coverage(b);
  EXPECT_NEAR(static_cast<double>(ca.foreground), static_cast<double>(cb.foreground),
              0.02 * static_cast<double>(ca.foreground));
  EXPECT_NEAR(ca.min_x, cb.min_x, 2);
  EXPECT_NEAR(ca.max_y, cb.max_y, 2);
}

TEST(Snapshot, CoarseAndFineMeshesDiffer) {
  RgbaImage coarse = render_or_fail(make_icosphere(1), small_request());
  RgbaImage fine = render_or_fail(make_icosphere(4), small_request());
  RgbaImage fine_again = render_or_fail(make_icosphere(4), small_request());
  // Rendering is deterministic, and resolution is visible (facets, silhouette).
  EXPECT_EQ(differing_pixels(fine, fine_again), 0u);
  EXPECT_GT(differing_pixels(coarse, fine), 320u * 240u / 50);
}

TEST(Snapshot, AsaKindsColouringDiffersFromShaded) {
  Mesh coarse = make_demo_mesh(2000);
  AsaOptions options;
  options.levels = 1;
  auto asa = subdivide(coarse, options);
  ASSERT_TRUE(asa.has_value()) << asa.error().message;
  size_t targets = 0, bisected = 0;
  for (FaceKind k : asa->face_kind) {
    targets += k == FaceKind::kTarget;
    bisected += k == FaceKind::kBisected;
  }
  ASSERT_GT(targets, 0u);

  OffscreenRequest shaded = small_request();
  OffscreenRequest kinds = small_request();
  kinds.style.coloring = ColorMode::kAsaKinds;
  kinds.face_kind = &asa->face_kind;
  RgbaImage a = render_or_fail(asa->mesh, shaded);
  RgbaImage b = render_or_fail(asa->mesh, kinds);
  EXPECT_GT(differing_pixels(a, b), foreground_coverage(a).foreground / 2);
  EXPECT_EQ(testing::orange_pixels(a), 0u);
  EXPECT_GT(testing::orange_pixels(b), 100u);
  if (bisected > 50) {
    EXPECT_GT(testing::green_pixels(b), 20u);
  }
}

TEST(Snapshot, WireframeAndDistanceModesChangeThePicture) {
  Mesh mesh = make_icosphere(2);
  OffscreenRequest plain = small_request();
  OffscreenRequest wire = small_request();
  wire.style.wireframe = true;
  RgbaImage a = render_or_fail(mesh, plain);
  RgbaImage b = render_or_fail(mesh, wire);
  EXPECT_GT(differing_pixels(a, b), 1000u);

  // Distance ramp: blue where the distance is 0, red at distance_max.
  std::vector<float> distance(mesh.vertex_count());
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v)
    distance[v] = mesh.positions[v].y > 0 ? 1.0f : 0.0f;
  OffscreenRequest ramp = small_request();
  ramp.style.coloring = ColorMode::kDistance;
  ramp.vertex_distance = &distance;
  ramp.pitch = 0;  // look from the side: upper half red, lower half blue
  RgbaImage c = render_or_fail(mesh, ramp);
  const uint8_t* top = c.pixel(160, 60);
  const uint8_t* bottom = c.pixel(160, 180);
  EXPECT_GT(top[0], top[2] + 40) << "top pixel should be red";
  EXPECT_GT(bottom[2], bottom[0] + 40) << "bottom pixel should be blue";
}

TEST(Snapshot, RenderSnapshotWritesThePng) {
  std::string path = temp_png("shaded");
  SnapshotOptions options;
  options.width = 200;
  options.height = 150;
  ASSERT_TRUE(render_snapshot(make_torus(), nullptr, options, path).has_value());
  auto read = read_png(path);
  ASSERT_TRUE(read.has_value()) << read.error().message;
  EXPECT_EQ(read->width, 200);
  EXPECT_EQ(read->height, 150);
  EXPECT_GT(foreground_coverage(*read).foreground, 200u * 150u / 8);
  std::remove(path.c_str());
}

TEST(Snapshot, BadInputIsAnErrorNotACrash) {
  Mesh broken = make_icosahedron();
  broken.triangles[3][1] = 999;
  auto a = render_offscreen(broken, small_request());
  ASSERT_FALSE(a.has_value());
  EXPECT_EQ(a.error().code, ErrorCode::kInvalidMesh);

  OffscreenRequest zero = small_request();
  zero.width = 0;
  auto b = render_offscreen(make_icosahedron(), zero);
  ASSERT_FALSE(b.has_value());
  EXPECT_EQ(b.error().code, ErrorCode::kInvalidArgument);

  auto c = render_snapshot(make_icosahedron(), nullptr, SnapshotOptions{},
                           "/nonexistent-dir/for/sure/x.png");
  ASSERT_FALSE(c.has_value());
  EXPECT_EQ(c.error().code, ErrorCode::kIo);
  EXPECT_NE(c.error().message.find("/nonexistent-dir"), std::string::npos);

  auto d = read_png("/nonexistent-dir/none.png");
  ASSERT_FALSE(d.has_value());
  EXPECT_EQ(d.error().code, ErrorCode::kIo);
}

TEST(Snapshot, EmptyMeshGivesBackgroundOnly) {
  auto image = render_offscreen(Mesh{}, small_request());
  ASSERT_TRUE(image.has_value()) << image.error().message;
  EXPECT_EQ(foreground_coverage(*image).foreground, 0u);
}

}  // namespace
}  // namespace meshstream::client
