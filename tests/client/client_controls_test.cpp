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
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/procedural.h"
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

class ClientControlsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto stream = encode_hcs(make_demo_mesh(20000));
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
  EXPECT_EQ(on->display->triangles, expected->mesh.triangles);
  EXPECT_GT(on->display->face_count(), asked->display->face_count());
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
}

}  // namespace
}  // namespace meshstream::client
