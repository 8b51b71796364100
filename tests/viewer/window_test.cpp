// The live window under a virtual X display: it opens, draws frames while
// another thread publishes a refining stream, shows the newest mesh and
// closes cleanly after exit_after_frames. Skips visibly without Xvfb.
#include "client/viewer/window.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <thread>

#include "common/asa/subdivide.h"
#include "common/mesh/procedural.h"
#include "tests/viewer/image_checks.h"
#include "tests/viewer/xvfb_display.h"

namespace meshstream::client {
namespace {

// Records what the viewer asked of the stream.
class FakeControls : public StreamControls {
 public:
  void set_asa(bool enabled, const AsaOptions& options) override {
    std::lock_guard lock(mutex_);
    enabled_ = enabled;
    options_ = options;
    ++set_asa_calls;
  }
  AsaOptions asa_options() const override {
    std::lock_guard lock(mutex_);
    return options_;
  }
  bool asa_enabled() const override {
    std::lock_guard lock(mutex_);
    return enabled_;
  }
  void pause() override {
    paused_ = true;
    ++pause_calls;
  }
  void resume() override {
    paused_ = false;
    ++resume_calls;
  }
  bool paused() const override { return paused_; }
  double current_rate_bytes_per_s() const override { return 12345.0; }

  std::atomic<int> set_asa_calls{0};
  std::atomic<int> pause_calls{0};
  std::atomic<int> resume_calls{0};

 private:
  mutable std::mutex mutex_;
  bool enabled_ = true;
  AsaOptions options_;
  std::atomic<bool> paused_{false};
};

class WindowTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (testing::XvfbDisplay::find_xvfb().empty()) {
      GTEST_SKIP() << "Xvfb is not installed (Debian package xvfb): window tests skipped";
    }
    std::string display = xvfb_.start();
    ASSERT_FALSE(display.empty()) << "Xvfb is installed but did not start";
    const char* old = std::getenv("DISPLAY");
    old_display_ = old ? old : "";
    had_display_ = old != nullptr;
    ::setenv("DISPLAY", display.c_str(), 1);
    ::unsetenv("WAYLAND_DISPLAY");
  }
  void TearDown() override {
    if (had_display_) {
      ::setenv("DISPLAY", old_display_.c_str(), 1);
    } else {
      ::unsetenv("DISPLAY");
    }
    xvfb_.stop();
  }

  testing::XvfbDisplay xvfb_;
  std::string old_display_;
  bool had_display_ = false;
};

ScriptedCommand at(uint64_t frame, ViewerCommand command) {
  ScriptedCommand c;
  c.at_frame = frame;
  c.command = command;
  return c;
}

// A stream of ever finer spheres with ASA labels, like the client publishes.
DisplayFrame make_frame(uint64_t sequence, uint32_t subdivisions, bool final) {
  DisplayFrame frame;
  frame.sequence = sequence;
  frame.records_decoded = static_cast<uint32_t>(sequence);
  frame.records_total = 4;
  frame.bytes_total = 4000;
  frame.bytes_received = 1000 * sequence;
  auto decoded = std::make_shared<Mesh>(make_icosphere(subdivisions));
  auto asa = subdivide(*decoded, AsaOptions{});
  if (asa) {
    frame.display = std::make_shared<Mesh>(std::move(asa->mesh));
    frame.face_kind = std::make_shared<std::vector<FaceKind>>(std::move(asa->face_kind));
  } else {
    frame.display = decoded;
  }
  frame.decoded = decoded;
  frame.final = final;
  return frame;
}

TEST_F(WindowTest, DrawsFramesWhileAStreamArrivesAndExitsCleanly) {
  LatestFrameMailbox mailbox;
  FakeControls controls;
  std::atomic<bool> published_all{false};
  std::thread publisher([&] {
    for (uint32_t i = 1; i <= 4; ++i) {
      mailbox.publish(make_frame(i, i, i == 4));
      std::this_thread::sleep_for(std::chrono::milliseconds(40));
    }
    published_all = true;
  });
  ViewerOptions options;
  options.width = 480;
  options.height = 360;
  options.exit_after_frames = 40;
  options.exit_screenshot =
      (std::filesystem::temp_directory_path() / "meshstream_viewer_window_exit.png").string();
  auto report = run_viewer_with_report(options, mailbox, controls);
  bool stream_ended_before_exit = published_all;
  publisher.join();
  ASSERT_TRUE(report.has_value()) << report.error().message;
  EXPECT_EQ(report->frames_drawn, 40u);
  EXPECT_GE(report->meshes_uploaded, 1u);
  EXPECT_LE(report->last_sequence_shown, 4u);
  if (stream_ended_before_exit) {
    EXPECT_EQ(report->last_sequence_shown, 4u) << "the final frame was missed";
  }
  EXPECT_EQ(controls.set_asa_calls, 0) << "no one touched the panel";
  // Once a mesh is up, every frame draws one; the frames before it are counted apart.
  EXPECT_EQ(report->frames_without_mesh, 0u);
  EXPECT_LT(report->frames_before_first_mesh, report->frames_drawn);
  EXPECT_GT(report->max_frame_ms, 0.0);

  // The window really showed a mesh: its last frame is not blank.
  auto image = read_png(options.exit_screenshot);
  ASSERT_TRUE(image.has_value()) << image.error().message;
  testing::keep_for_inspection(*image, "window_exit");
  auto coverage = testing::foreground_coverage(*image);
  EXPECT_GT(coverage.foreground, static_cast<size_t>(image->width) * image->height / 10);
  std::filesystem::remove(options.exit_screenshot);
}

TEST_F(WindowTest, ShowsTheNewestFrameOnceTheStreamEnds) {
  LatestFrameMailbox mailbox;
  FakeControls controls;
  for (uint32_t i = 1; i <= 3; ++i) mailbox.publish(make_frame(i, i, i == 3));
  ViewerOptions options;
  options.width = 320;
  options.height = 240;
  options.exit_after_frames = 5;
  options.exit_screenshot =
      (std::filesystem::temp_directory_path() / "meshstream_viewer_window_panel.png").string();
  options.exit_screenshot_with_panel = true;
  auto report = run_viewer_with_report(options, mailbox, controls);
  ASSERT_TRUE(report.has_value()) << report.error().message;
  // Latest wins: the older frames were never uploaded.
  EXPECT_EQ(report->meshes_uploaded, 1u);
  EXPECT_EQ(report->last_sequence_shown, 3u);
  auto image = read_png(options.exit_screenshot);
  ASSERT_TRUE(image.has_value()) << image.error().message;
  testing::keep_for_inspection(*image, "window_panel");
  std::filesystem::remove(options.exit_screenshot);
}

TEST_F(WindowTest, CommandsSteerTheStreamAndTheView) {
  LatestFrameMailbox mailbox;
  FakeControls controls;
  for (uint32_t i = 1; i <= 3; ++i) mailbox.publish(make_frame(i, i, i == 3));
  AsaOptions asa;
  asa.levels = 2;
  asa.flatness = 0.9f;
  asa.rule = ButterflyRule::kProjection;
  asa.crease_degrees = 30;
  ScriptedCommand set_asa = at(5, ViewerCommand::kSetAsa);
  set_asa.asa_enabled = true;
  set_asa.asa = asa;
  std::vector<ScriptedCommand> script{
      at(2, ViewerCommand::kTogglePause),
      at(4, ViewerCommand::kTogglePause),
      set_asa,
      at(6, ViewerCommand::kColorDistance),
      at(7, ViewerCommand::kToggleWireframe),
      at(8, ViewerCommand::kScreenshot),
      at(9, ViewerCommand::kFrameModel),
      at(40, ViewerCommand::kClose),
  };
  ViewerOptions options;
  options.width = 320;
  options.height = 240;
  options.exit_after_frames = 1000;  // kClose ends it first
  options.screenshot_dir = std::filesystem::temp_directory_path().string();
  auto report = run_viewer_with_report(options, mailbox, controls, script);
  ASSERT_TRUE(report.has_value()) << report.error().message;
  EXPECT_EQ(report->frames_drawn, 41u);  // the close request's frame is still drawn
  EXPECT_EQ(controls.pause_calls, 1);
  EXPECT_EQ(controls.resume_calls, 1);
  EXPECT_FALSE(controls.paused());
  ASSERT_EQ(controls.set_asa_calls, 1);
  EXPECT_TRUE(controls.asa_enabled());
  EXPECT_EQ(controls.asa_options().levels, 2);
  EXPECT_EQ(controls.asa_options().rule, ButterflyRule::kProjection);
  EXPECT_FLOAT_EQ(controls.asa_options().crease_degrees, 30.0f);
  EXPECT_EQ(report->final_coloring, 2);
  EXPECT_TRUE(report->final_wireframe);
  // The final mesh was known from the start, so distances reached the GPU.
  EXPECT_GE(report->distance_uploads, 1u);
  ASSERT_EQ(report->screenshots.size(), 1u);
  auto shot = read_png(report->screenshots[0]);
  ASSERT_TRUE(shot.has_value()) << shot.error().message;
  EXPECT_EQ(shot->width, 320);
  EXPECT_GT(testing::foreground_coverage(*shot).foreground, 320u * 240u / 10);
  testing::keep_for_inspection(*shot, "window_screenshot_distance_wire");
  std::filesystem::remove(report->screenshots[0]);
}

TEST_F(WindowTest, DistanceColouringShowsWhereTheDisplayLeavesTheFinalMesh) {
  LatestFrameMailbox mailbox;
  FakeControls controls;
  // Final frame: the display bulges out of the decoded (final) mesh on its
  // upper half only, so the upper half must turn warm and the lower stay blue.
  DisplayFrame frame = make_frame(1, 3, true);
  auto display = std::make_shared<Mesh>(*frame.decoded);
  for (Vec3f& p : display->positions) {
    if (p.y > 0) p = p * 1.2f;
  }
  frame.display = display;
  frame.face_kind = nullptr;
  mailbox.publish(frame);
  ViewerOptions options;
  options.width = 400;
  options.height = 300;
  options.initial_coloring = 2;
  options.exit_after_frames = 1000;
  options.screenshot_dir = std::filesystem::temp_directory_path().string();
  std::vector<ScriptedCommand> script;
  // Screenshots now and then; the distances arrive from the worker within
  // a few frames, the last one must show them.
  for (uint64_t f = 20; f <= 120; f += 20) script.push_back(at(f, ViewerCommand::kScreenshot));
  script.push_back(at(121, ViewerCommand::kClose));
  auto report = run_viewer_with_report(options, mailbox, controls, script);
  ASSERT_TRUE(report.has_value()) << report.error().message;
  ASSERT_GE(report->distance_uploads, 1u);
  ASSERT_FALSE(report->screenshots.empty());
  auto shot = read_png(report->screenshots.back());
  ASSERT_TRUE(shot.has_value());
  testing::keep_for_inspection(*shot, "window_distance_bulge");
  size_t warm = 0, blue = 0;
  for (size_t i = 0; i + 3 < shot->rgba.size(); i += 4) {
    int r = shot->rgba[i], b = shot->rgba[i + 2];
    warm += r > b + 60 ? 1 : 0;
    blue += b > r + 60 ? 1 : 0;
  }
  EXPECT_GT(warm, 2000u);
  EXPECT_GT(blue, 2000u);
  for (const std::string& path : report->screenshots) std::filesystem::remove(path);
}

TEST_F(WindowTest, RefusesABrokenMeshWithoutCrashing) {
  LatestFrameMailbox mailbox;
  FakeControls controls;
  DisplayFrame frame = make_frame(1, 1, false);
  auto broken = std::make_shared<Mesh>(*frame.decoded);
  broken->triangles[0][0] = 1u << 30;  // far outside the vertex array
  frame.display = broken;
  mailbox.publish(frame);
  ViewerOptions options;
  options.width = 160;
  options.height = 120;
  options.exit_after_frames = 3;
  auto report = run_viewer_with_report(options, mailbox, controls);
  ASSERT_TRUE(report.has_value()) << report.error().message;
  EXPECT_EQ(report->rejected_meshes, 1u);
  EXPECT_EQ(report->meshes_uploaded, 0u);
}

TEST(WindowWithoutDisplay, IsUnsupportedNotACrash) {
  const char* old = std::getenv("DISPLAY");
  std::string saved = old ? old : "";
  ::unsetenv("DISPLAY");
  ::unsetenv("WAYLAND_DISPLAY");
  LatestFrameMailbox mailbox;
  FakeControls controls;
  Status status = run_viewer(ViewerOptions{}, mailbox, controls);
  if (old) ::setenv("DISPLAY", saved.c_str(), 1);
  ASSERT_FALSE(status.has_value());
  EXPECT_EQ(status.error().code, ErrorCode::kUnsupported);
  EXPECT_NE(status.error().message.find("display"), std::string::npos) << status.error().message;
}

}  // namespace
}  // namespace meshstream::client
