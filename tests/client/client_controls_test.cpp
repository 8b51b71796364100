// The client library against the real server, in-process: what a viewer
// does through StreamControls (pause and resume the network reads, re-run
// ASA with new options on the current mesh) and what it sees in the
// latest-wins mailbox.
#include <gtest/gtest.h>

#include <fstream>
#include <thread>

#include "client/decoded_stream.h"
#include "client/display_pipeline.h"
#include "client/stream_client.h"
#include "common/asa/view.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/procedural.h"
#include "tests/asa/asa_test_support.h"
#include "tests/client/client_harness.h"

namespace meshstream::client {
namespace {

using clienttest::Server;
using clienttest::TempDir;
using namespace std::chrono_literals;

struct Session {
  DecodedStream decoded;
  LatestFrameMailbox mailbox;
  std::unique_ptr<SourceOf<StreamClient>> client;
  std::unique_ptr<DisplayPipeline> pipeline;
  std::thread network;

  Session(const Server& server, PipelineSettings settings) {
    StreamTarget t;
    t.host = "127.0.0.1";
    t.port = server.port();
    t.model = "demo";
    client = std::make_unique<SourceOf<StreamClient>>(t);
    pipeline = std::make_unique<DisplayPipeline>(decoded, client.get(), mailbox, settings, nullptr);
    network = std::thread([this] {
      client->run(decoded, [this](const StreamFacts& f) {
        pipeline->set_totals(f.total_bytes, f.records_total, f.end_record);
      });
    });
    pipeline->start();
  }
  ~Session() {
    client->stop();
    if (network.joinable()) network.join();
    pipeline->stop();
  }
};

// The fitted camera moved to 0.4 of its distance and turned about a
// quarter round the target: a view the fit did not refine for.
AsaCamera close_up_and_turned(const AsaCamera& fitted) {
  AsaCamera close = fitted;
  close.eye =
      close.target + Vec3f{close.eye.z - close.target.z, 0.2f * (close.eye.y - close.target.y),
                           close.target.x - close.eye.x} *
                         0.4f;
  return close;
}

class ClientControlsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    EncodeOptions options;
    options.asa_guidance = false;  // no test here follows the guidance
    auto stream = encode_hcs(make_demo_mesh(20000), options);
    ASSERT_TRUE(stream);
    bytes_ = *stream;
    std::filesystem::create_directories(dir_ / "models");
    std::ofstream(dir_ / "models/demo.hcs", std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes_.data()), std::streamsize(bytes_.size()));
  }
  TempDir dir_;
  std::vector<uint8_t> bytes_;
};

TEST_F(ClientControlsTest, PauseStopsTheReadsAndResumeFinishesTheSameMesh) {
  Server server;
  ASSERT_TRUE(server.start({"--models", dir_ / "models", "--cache", dir_ / "cache", "--rate",
                            "40000", "--max-chunk-bytes", "1024"},
                           dir_.path()))
      << server.log();
  PipelineSettings settings;
  settings.asa_enabled = false;
  Session s(server, settings);
  // Wait for the first frame, then pause.
  auto first = s.mailbox.wait_newer(0);
  ASSERT_TRUE(first);
  s.pipeline->pause();
  EXPECT_TRUE(s.pipeline->paused());
  std::this_thread::sleep_for(150ms);  // a chunk in flight may still land
  const uint32_t at_pause = s.decoded.records_decoded();
  std::this_thread::sleep_for(400ms);
  EXPECT_EQ(s.decoded.records_decoded(), at_pause) << "records arrived while paused";
  EXPECT_FALSE(s.decoded.outcome().has_value());
  s.pipeline->resume();
  ASSERT_TRUE(s.pipeline->wait_finished());
  auto last = s.mailbox.take_newer(0);
  ASSERT_TRUE(last);
  EXPECT_TRUE(last->final);
  auto expected = decode_hcs(bytes_);
  ASSERT_TRUE(expected);
  EXPECT_EQ(last->decoded->triangles, expected->triangles);
  EXPECT_EQ(last->decoded->positions.size(), expected->positions.size());
  EXPECT_GT(at_pause, 0u);
  EXPECT_LT(at_pause, last->records_decoded);
}

// The same triangles at the same positions (corner bits), in any order.
::testing::AssertionResult same_faces(const Mesh& a, const Mesh& b) {
  if (a.face_count() != b.face_count())
    return ::testing::AssertionFailure() << a.face_count() << " faces against " << b.face_count();
  // As sets: ASA's incremental path keeps its faces in its own order.
  if (asa_test::face_set(a, nullptr) != asa_test::face_set(b, nullptr))
    return ::testing::AssertionFailure() << "the faces differ";
  return ::testing::AssertionSuccess();
}

TEST_F(ClientControlsTest, SetAsaReRunsOnTheCurrentMesh) {
  Server server;
  ASSERT_TRUE(server.start({"--models", dir_ / "models", "--cache", dir_ / "cache"}, dir_.path()))
      << server.log();
  PipelineSettings settings;  // ASA on, 1 level, on the whole mesh (as subdivide())
  settings.view.dependent = false;
  Session s(server, settings);
  ASSERT_TRUE(s.pipeline->wait_finished());
  auto final_frame = s.mailbox.take_newer(0);
  ASSERT_TRUE(final_frame && final_frame->final);
  // The complete stream is shown as decoded (issue 20: nothing is missing).
  EXPECT_EQ(final_frame->display, final_frame->decoded);

  // Asking for ASA (the viewer's panel) applies it to the complete mesh.
  s.pipeline->set_asa(true, s.pipeline->asa_options());
  auto asked = s.mailbox.wait_newer(final_frame->sequence);
  ASSERT_TRUE(asked);
  EXPECT_GT(asked->display->face_count(), asked->decoded->face_count());

  // Off: the display becomes the decoded mesh.
  s.pipeline->set_asa(false, s.pipeline->asa_options());
  auto off = s.mailbox.wait_newer(asked->sequence);
  ASSERT_TRUE(off);
  EXPECT_FALSE(s.pipeline->asa_enabled());
  EXPECT_EQ(off->display->face_count(), off->decoded->face_count());
  EXPECT_EQ(off->records_decoded, final_frame->records_decoded);

  // Two levels: more than one level gave, and exactly what subdivide() gives.
  AsaOptions two;
  two.levels = 2;
  s.pipeline->set_asa(true, two);
  auto on = s.mailbox.wait_newer(off->sequence);
  ASSERT_TRUE(on);
  EXPECT_EQ(s.pipeline->asa_options().levels, 2);
  auto expected = subdivide(*on->decoded, two);
  ASSERT_TRUE(expected);
  EXPECT_TRUE(same_faces(*on->display, expected->mesh));
  EXPECT_GT(on->display->face_count(), asked->display->face_count());
}

// The viewer's live controls (issue 16): a new camera or pixel tolerance
// re-runs view-dependent ASA on the current mesh for that view, the faces
// subdivide() gives at that camera and tolerance, and the frame says
// which camera and tolerance it was refined for.
TEST_F(ClientControlsTest, ViewerCameraAndToleranceReRunForThatView) {
  Server server;
  ASSERT_TRUE(server.start({"--models", dir_ / "models", "--cache", dir_ / "cache"}, dir_.path()))
      << server.log();
  PipelineSettings settings;  // view-dependent ASA, 1 level, tolerance 2
  settings.asa_on_complete = true;
  Session s(server, settings);
  ASSERT_TRUE(s.pipeline->wait_finished());
  auto done = s.mailbox.take_newer(0);
  ASSERT_TRUE(done && done->final && done->camera);
  EXPECT_EQ(done->pixel_tolerance, 2.0f);
  EXPECT_EQ(s.pipeline->pixel_tolerance(), 2.0f);
  const Mesh& decoded = *done->decoded;
  auto expected_for = [&](const AsaCamera& camera, float tolerance) {
    AsaOptions o;
    o.view.enabled = true;
    o.view.camera = camera;
    o.view.pixel_tolerance = tolerance;
    o.view.facing_sign = facing_sign_of(decoded);
    auto r = subdivide(decoded, o);
    EXPECT_TRUE(r.has_value());
    return r ? r->mesh : Mesh{};
  };
  EXPECT_TRUE(same_faces(*done->display, expected_for(*done->camera, 2)));

  // The window's camera, close up and turned: the display follows it.
  const AsaCamera close = close_up_and_turned(*done->camera);
  s.pipeline->set_view_camera(close);
  auto moved = s.mailbox.wait_newer(done->sequence);
  ASSERT_TRUE(moved && moved->camera);
  EXPECT_EQ(moved->camera->eye, close.eye);
  EXPECT_EQ(moved->decoded, done->decoded) << "a camera move is no new record";
  const Mesh at_close = expected_for(close, 2);
  EXPECT_NE(at_close.face_count(), done->display->face_count()) << "the camera made no difference";
  EXPECT_TRUE(same_faces(*moved->display, at_close));

  // A coarser tolerance (the panel's slider): fewer faces, the same as subdivide().
  s.pipeline->set_pixel_tolerance(12);
  EXPECT_EQ(s.pipeline->pixel_tolerance(), 12.0f);
  auto coarse = s.mailbox.wait_newer(moved->sequence);
  ASSERT_TRUE(coarse);
  EXPECT_EQ(coarse->pixel_tolerance, 12.0f);
  EXPECT_LT(coarse->display->face_count(), moved->display->face_count());
  EXPECT_TRUE(same_faces(*coarse->display, expected_for(close, 12)));
  // A tolerance at or below 0 is ignored (the panel cannot send one).
  s.pipeline->set_pixel_tolerance(0);
  EXPECT_EQ(s.pipeline->pixel_tolerance(), 12.0f);
}

// With a renderer (--view), an update with new records is culled for it at
// once, a re-run for a moved camera alone is not (the window draws the whole
// display while its camera moves), and once the camera rests the pipeline
// publishes that same display again, culled for that camera exactly as
// cull_display culls it.
TEST_F(ClientControlsTest, ACameraReRunOwesTheRenderersCullUntilTheCameraRests) {
  Server server;
  ASSERT_TRUE(server.start({"--models", dir_ / "models", "--cache", dir_ / "cache"}, dir_.path()))
      << server.log();
  PipelineSettings settings;
  settings.asa_on_complete = true;
  settings.view.cull_for_renderer = true;
  Session s(server, settings);
  ASSERT_TRUE(s.pipeline->wait_finished());
  auto done = s.mailbox.take_newer(0);
  ASSERT_TRUE(done && done->final && done->camera && done->drawn);
  auto direct_cull = [](const DisplayFrame& frame, const AsaCamera& camera) {
    auto source = analyze_source_topology(*frame.decoded);
    auto display = analyze_display_topology(*frame.display, *source);
    return cull_display(frame.display, frame.face_kind, *display, camera);
  };
  // New records: culled as they come.
  EXPECT_TRUE(done->topology);
  EXPECT_GT(done->cull_ms, 0);
  EXPECT_TRUE(same_faces(*done->drawn, *direct_cull(*done, *done->camera).mesh));

  const AsaCamera close = close_up_and_turned(*done->camera);
  s.pipeline->set_view_camera(close);
  auto moved = s.mailbox.wait_newer(done->sequence);
  ASSERT_TRUE(moved && moved->camera && moved->display);
  EXPECT_EQ(moved->camera->eye, close.eye);
  EXPECT_NE(moved->display, done->display) << "the camera move re-ran ASA";
  EXPECT_EQ(moved->drawn, moved->display) << "a camera-only re-run draws the whole display";
  EXPECT_EQ(moved->drawn_face_kind, moved->face_kind);
  EXPECT_TRUE(moved->cull.everything);
  EXPECT_FALSE(moved->topology);
  EXPECT_EQ(moved->cull_ms, 0);

  // Nothing more comes: the camera rests, and the cull it owed arrives.
  auto rested = s.mailbox.wait_newer(moved->sequence);
  ASSERT_TRUE(rested && rested->camera && rested->drawn);
  EXPECT_EQ(rested->camera->eye, close.eye);
  EXPECT_EQ(rested->display, moved->display) << "the same display, only culled";
  EXPECT_EQ(rested->decoded, moved->decoded);
  EXPECT_EQ(rested->asa_ms, 0);
  EXPECT_GT(rested->cull_ms, 0);
  EXPECT_TRUE(rested->topology);
  EXPECT_FALSE(rested->cull.everything);
  const CulledDisplay direct = direct_cull(*rested, close);
  EXPECT_LT(direct.mesh->face_count(), rested->display->face_count())
      << "this close-up leaves nothing out: the test shows nothing";
  EXPECT_EQ(rested->drawn->face_count(), direct.mesh->face_count());
  EXPECT_TRUE(same_faces(*rested->drawn, *direct.mesh));
  // Paid once: no further frame while nothing changes.
  std::this_thread::sleep_for(600ms);
  EXPECT_FALSE(s.mailbox.take_newer(rested->sequence));
}

// Network reads never wait for ASA: with ASA far slower than the stream,
// the network side has every record long before the pipeline is done, and
// the pipeline shows the newest mesh, merging the records in between.
TEST_F(ClientControlsTest, NetworkNeverWaitsForASlowPipeline) {
  Server server;
  ASSERT_TRUE(server.start(
      {"--models", dir_ / "models", "--cache", dir_ / "cache", "--max-chunk-bytes", "1024"},
      dir_.path()))
      << server.log();
  PipelineSettings settings;
  settings.asa.levels = 3;  // tens of ms per update on this mesh
  settings.path = AsaPath::kFull;
  Session s(server, settings);
  const auto start = std::chrono::steady_clock::now();
  s.network.join();  // the network side ends on its own
  const auto network_done = std::chrono::steady_clock::now();
  ASSERT_TRUE(s.decoded.outcome() && s.decoded.outcome()->ok);
  ASSERT_TRUE(s.pipeline->wait_finished());
  const auto pipeline_done = std::chrono::steady_clock::now();
  auto last = s.mailbox.take_newer(0);
  ASSERT_TRUE(last && last->final);
  EXPECT_LT(network_done - start, pipeline_done - start);
  // Fewer frames than records: the records that arrived during a run of
  // ASA were merged into the next frame.
  EXPECT_LT(last->sequence, last->records_decoded);
  // The complete mesh is shown as decoded, without waiting for a run of ASA
  // on an older prefix (dropped when the last record came during one).
  EXPECT_EQ(last->display, last->decoded);
  EXPECT_EQ(last->records_decoded, last->records_total);
  // Whatever was dropped, ASA asked for afterwards is exact.
  s.pipeline->set_asa(true, settings.asa);
  auto after = s.mailbox.wait_newer(last->sequence);
  ASSERT_TRUE(after && after->camera);
  AsaOptions expected = settings.asa;
  expected.view.enabled = true;
  expected.view.camera = *after->camera;
  expected.view.facing_sign = facing_sign_of(*after->decoded);
  auto full = subdivide(*after->decoded, expected);
  ASSERT_TRUE(full);
  EXPECT_TRUE(same_faces(*after->display, full->mesh));
}

}  // namespace
}  // namespace meshstream::client
