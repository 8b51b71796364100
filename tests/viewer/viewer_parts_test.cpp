// The viewer's pieces that need no GL context: the orbit camera's framing
// and gestures, the bounded frame history, per-vertex distances to the final
// mesh (and their worker thread), PNG round trips.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <thread>

#include "client/viewer/camera.h"
#include "client/viewer/frame_history.h"
#include "client/viewer/rgba_image.h"
#include "client/viewer/vertex_distances.h"
#include "common/mesh/procedural.h"

namespace meshstream::client {
namespace {

// Normalized device coordinates of p.
Vec3f project(const OrbitCamera& camera, float aspect, Vec3f p) {
  Mat4 m = mat4_multiply(camera.projection(aspect), camera.view());
  float x = m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12];
  float y = m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13];
  float z = m[2] * p.x + m[6] * p.y + m[10] * p.z + m[14];
  float w = m[3] * p.x + m[7] * p.y + m[11] * p.z + m[15];
  return {x / w, y / w, z / w};
}

TEST(OrbitCamera, FrameFitsEveryVertexAndFillsTheView) {
  Mesh mesh = make_demo_mesh(4000);
  for (Vec3f& p : mesh.positions) p = p * 40.0f + Vec3f{-100, 3, 9};  // any scale and place
  for (float aspect : {0.5f, 1.0f, 2.0f}) {
    OrbitCamera camera;
    camera.frame(mesh, aspect, 0.8f);
    float extent_x = 0, extent_y = 0;
    for (const Vec3f& p : mesh.positions) {
      Vec3f ndc = project(camera, aspect, p);
      ASSERT_LT(std::abs(ndc.x), 0.82f);
      ASSERT_LT(std::abs(ndc.y), 0.82f);
      ASSERT_GT(ndc.z, -1.0f);  // between the clip planes
      ASSERT_LT(ndc.z, 1.0f);
      extent_x = std::max(extent_x, std::abs(ndc.x));
      extent_y = std::max(extent_y, std::abs(ndc.y));
    }
    EXPECT_GT(std::max(extent_x, extent_y), 0.75f) << "aspect " << aspect;
  }
}

TEST(OrbitCamera, GesturesMoveTheRightThings) {
  OrbitCamera camera;
  camera.frame(make_icosphere(2), 1.0f);
  Vec3f target = camera.target;
  float distance = camera.distance;
  camera.orbit(100, 0);  // orbit keeps target and distance
  EXPECT_EQ(camera.target, target);
  EXPECT_FLOAT_EQ(camera.distance, distance);
  camera.zoom(2);  // closer
  EXPECT_LT(camera.distance, distance);
  camera.zoom(-2);
  EXPECT_NEAR(camera.distance, distance, 1e-4f * distance);
  Vec3f eye_before = camera.eye();
  camera.pan(50, 0, 600);  // pan moves target and eye together, across the view
  Vec3f moved = camera.target - target;
  EXPECT_GT(length(moved), 0.0f);
  Vec3f eye_moved = camera.eye() - eye_before;
  EXPECT_NEAR(length(eye_moved - moved), 0.0f, 1e-5f);
  Vec3f view_dir = normalized(target - eye_before);
  EXPECT_NEAR(dot(normalized(moved), view_dir), 0.0f, 1e-5f);
  camera.orbit(0, 1e6f);  // pitch is clamped short of the pole
  EXPECT_LT(camera.pitch, 1.5708f);
}

DisplayFrame frame_with_sequence(uint64_t sequence) {
  DisplayFrame frame;
  frame.sequence = sequence;
  return frame;
}

TEST(FrameHistory, StaysBoundedAndSpreadOverTheStream) {
  FrameHistory history(8);
  for (uint64_t s = 1; s <= 1000; ++s) {
    history.add(frame_with_sequence(s));
    ASSERT_LE(history.size(), 8u);
    ASSERT_EQ(history.newest().sequence, s);
    ASSERT_EQ(history[0].sequence, 1u);
    for (size_t i = 1; i < history.size(); ++i)
      ASSERT_LT(history[i - 1].sequence, history[i].sequence);
  }
  // Spread: evenly over the whole stream, not crowded at the end.
  ASSERT_GE(history.size(), 5u);
  EXPECT_LT(history[history.size() / 2].sequence, 700u);
  EXPECT_GT(history[history.size() / 2].sequence, 300u);
}

TEST(VertexDistances, AreExactForConcentricSpheres) {
  Mesh unit = make_icosphere(3);
  TriangleBvh bvh = TriangleBvh::build(unit);
  std::vector<float> to_itself = vertex_distances(unit, bvh);
  for (float d : to_itself) ASSERT_LT(d, 1e-6f);

  Mesh bigger = unit;
  for (Vec3f& p : bigger.positions) p = p * 1.5f;
  std::vector<float> d = vertex_distances(bigger, bvh);
  for (float v : d) {
    // Vertices sit 0.5 above the unit sphere's vertices; the polyhedron's
    // faces are a little inside the sphere, so distances are at least 0.5.
    ASSERT_GE(v, 0.5f - 1e-5f);
    ASSERT_LT(v, 0.52f);
  }
}

TEST(DistanceWorker, AnswersTheNewestRequestAgainstTheReference) {
  auto reference = std::make_shared<Mesh>(make_icosphere(3));
  auto near_mesh = std::make_shared<Mesh>(*reference);
  for (Vec3f& p : const_cast<Mesh&>(*near_mesh).positions) p = p * 1.25f;
  DistanceWorker worker;
  EXPECT_FALSE(worker.has_reference());
  worker.set_reference(reference);
  EXPECT_TRUE(worker.has_reference());
  worker.request(reference, 1);
  worker.request(near_mesh, 2);  // the newest request wins
  std::optional<DistanceWorker::Answer> answer;
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < deadline) {
    answer = worker.take_result();
    if (answer && answer->tag == 2) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(answer.has_value());
  ASSERT_EQ(answer->tag, 2u);
  ASSERT_EQ(answer->distances.size(), near_mesh->vertex_count());
  EXPECT_NEAR(answer->max, 0.25f, 0.02f);
  EXPECT_LE(answer->p98, answer->max);
  EXPECT_GE(answer->p98, 0.25f - 1e-5f);
  EXPECT_NEAR(answer->reference_diagonal, 2 * std::sqrt(3.0f), 0.05f);
}

TEST(Png, RoundTripsExactly) {
  RgbaImage image;
  image.width = 7;
  image.height = 3;
  for (int i = 0; i < 7 * 3 * 4; ++i) image.rgba.push_back(static_cast<uint8_t>(i * 37 + 11));
  std::string path =
      (std::filesystem::temp_directory_path() / "meshstream_viewer_roundtrip.png").string();
  ASSERT_TRUE(write_png(path, image).has_value());
  auto back = read_png(path);
  ASSERT_TRUE(back.has_value()) << back.error().message;
  EXPECT_EQ(back->width, 7);
  EXPECT_EQ(back->height, 3);
  EXPECT_EQ(back->rgba, image.rgba);
  std::filesystem::remove(path);

  RgbaImage flipped = image;
  flip_rows(flipped);
  EXPECT_EQ(flipped.pixel(0, 0)[0], image.pixel(0, 2)[0]);
  flip_rows(flipped);
  EXPECT_EQ(flipped.rgba, image.rgba);

  RgbaImage wrong = image;
  wrong.rgba.pop_back();
  auto status = write_png(path, wrong);
  ASSERT_FALSE(status.has_value());
  EXPECT_EQ(status.error().code, ErrorCode::kInvalidArgument);
}

TEST(Png, NotAPngIsAParseError) {
  std::string path =
      (std::filesystem::temp_directory_path() / "meshstream_viewer_not.png").string();
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    std::fputs("this is not a png file at all", f);
    std::fclose(f);
  }
  auto image = read_png(path);
  ASSERT_FALSE(image.has_value());
  EXPECT_EQ(image.error().code, ErrorCode::kParse);
  EXPECT_NE(image.error().message.find(path), std::string::npos);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace meshstream::client
