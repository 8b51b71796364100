// The encoder on meshes big enough for its threads to matter (the
// decimation splits its costs into 4096-vertex blocks): the same stream for
// every thread count, and a progress report that moves forward smoothly.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "common/codec/encoder.h"
#include "common/mesh/procedural.h"

namespace meshstream {
namespace {

// About 30k vertices: several decimation blocks per thread.
const Mesh& scale_mesh() {
  static const Mesh mesh = make_demo_mesh(60'000);
  return mesh;
}

TEST(EncoderThreads, TheStreamIsTheSameForEveryThreadCount) {
  const Mesh& mesh = scale_mesh();
  ASSERT_GT(mesh.vertex_count(), 6u * 4096);
  EncodeOptions one;
  one.threads = 1;
  auto reference = encode_hcs(mesh, one);
  ASSERT_TRUE(reference) << reference.error().message;
  for (uint32_t threads : {0u, 2u, 5u}) {
    EncodeOptions options;
    options.threads = threads;
    auto stream = encode_hcs(mesh, options);
    ASSERT_TRUE(stream) << stream.error().message;
    EXPECT_EQ(*stream, *reference) << threads << " threads";
  }
}

struct Call {
  std::string stage;
  double fraction;
};

std::vector<Call> progress_of(const Mesh& mesh, EncodeOptions options) {
  std::vector<Call> calls;
  options.progress = [&calls](const EncodeProgress& p) {
    calls.push_back({std::string(p.stage), p.fraction});
  };
  auto stream = encode_hcs(mesh, options);
  EXPECT_TRUE(stream);
  return calls;
}

// Stages in order, fractions never decreasing and within [0, 1], ending at
// "done" 1; each long stage advances in many small steps, not one jump;
// a few hundred calls at most; and the stream does not depend on it.
TEST(EncoderThreads, ProgressAdvancesSmoothlyThroughTheStages) {
  const Mesh& mesh = scale_mesh();
  for (uint32_t threads : {1u, 0u}) {
    EncodeOptions options;
    options.threads = threads;
    const std::vector<Call> calls = progress_of(mesh, options);
    ASSERT_FALSE(calls.empty());
    EXPECT_LE(calls.size(), 800u);
    EXPECT_EQ(calls.back().stage, "done");
    EXPECT_DOUBLE_EQ(calls.back().fraction, 1.0);
    const std::vector<std::string> order = {
        "decimating",        "coding records",         "measuring",
        "coding the winner", "measuring ASA guidance", "done"};
    size_t stage = 0;
    std::vector<int> calls_in(order.size(), 0);
    for (size_t i = 0; i < calls.size(); ++i) {
      EXPECT_GE(calls[i].fraction, 0.0);
      EXPECT_LE(calls[i].fraction, 1.0);
      if (i > 0) {
        EXPECT_GE(calls[i].fraction, calls[i - 1].fraction) << i;
      }
      while (stage < order.size() && calls[i].stage != order[stage]) ++stage;
      ASSERT_LT(stage, order.size()) << "stage " << calls[i].stage << " out of order";
      ++calls_in[stage];
    }
    EXPECT_GE(calls_in[0], 5) << "decimating";
    EXPECT_GE(calls_in[1], 20) << "coding records";
    EXPECT_GE(calls_in[2], 3) << "measuring";
    EXPECT_GE(calls_in[4], 3) << "measuring ASA guidance";
    // No jump of more than a fifth of the whole between two calls.
    for (size_t i = 1; i < calls.size(); ++i)
      EXPECT_LE(calls[i].fraction - calls[i - 1].fraction, 0.2) << i << " " << calls[i].stage;
  }
  EncodeOptions quiet;
  EncodeOptions watched;
  watched.progress = [](const EncodeProgress&) {};
  EXPECT_EQ(*encode_hcs(mesh, quiet), *encode_hcs(mesh, watched));
}

}  // namespace
}  // namespace meshstream
