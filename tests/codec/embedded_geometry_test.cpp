// Successive approximation (embedded_geometry.h): plane steps written with
// the true residual and read back give the same state; every step keeps the
// true position inside the known interval, the reconstruction error never
// exceeds half the interval, and shift 0 is exact. Also: streams of issue
// I's format (container 1, refinement format 1) still decode.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <random>

#include "common/codec/decoder.h"
#include "common/codec/embedded_geometry.h"

namespace meshstream {
namespace {

TEST(EmbeddedGeometry, PlaneStepsRoundTripAndConverge) {
  std::mt19937 rng(5);
  const int32_t max = 4095;
  for (int trial = 0; trial < 2000; ++trial) {
    const bool base = trial % 3 == 0;
    const int shift = 1 + int(rng() % 8);
    VertexGeometry g;
    Vec3i truth, residual;
    for (int a = 0; a < 3; ++a) {
      if (base) {
        truth[a] = int32_t(rng() % (max + 1));
        g.anchor[a] = (truth[a] >> shift) << shift;
        residual[a] = truth[a] - g.anchor[a];
      } else {
        g.anchor[a] = int32_t(rng() % (max + 1));
        const int32_t spread = int32_t(1 + rng() % 600);
        truth[a] = std::clamp<int32_t>(g.anchor[a] + int32_t(rng() % (2 * spread + 1)) - spread, 0, max);
        residual[a] = truth[a] - g.anchor[a];
        g.mag[a] = uint32_t(std::abs(residual[a])) >> shift;
        if (g.mag[a] > 0 && residual[a] < 0) g.negative |= uint8_t(1u << a);
      }
    }
    g.shift = uint8_t(shift);
    g.normal_axis = base ? kBaseVertexAxis : uint8_t(rng() % 3);
    VertexGeometry enc_g = g, dec_g = g;
    GeometryModels enc_m, dec_m;
    RangeEncoder enc;
    uint8_t prev_enc = 0;
    std::vector<VertexGeometry> states;
    while (enc_g.shift > 0) {
      PlaneBitWriter io{enc, residual};
      ASSERT_TRUE(plane_step(enc_m, io, enc_g, prev_enc, max));
      states.push_back(enc_g);
      const Vec3i p = reconstruct(enc_g, max);
      for (int a = 0; a < 3; ++a) {
        // The reconstruction is within half the known interval (a dead-zone
        // axis within the whole interval: it shows the anchor).
        const int64_t err = std::abs(int64_t(p[a]) - truth[a]);
        const bool deadzone = !base && enc_g.mag[a] == 0;
        EXPECT_LE(err, deadzone ? (int64_t(1) << enc_g.shift) - 1 : (int64_t(1) << enc_g.shift) / 2 + 1);
      }
    }
    EXPECT_EQ(reconstruct(enc_g, max), truth) << "shift 0 is exact";
    const std::vector<uint8_t> bytes = enc.finish();
    RangeDecoder dec(bytes);
    PlaneBitReader rio{dec};
    uint8_t prev_dec = 0;
    for (const VertexGeometry& want : states) {
      ASSERT_TRUE(plane_step(dec_m, rio, dec_g, prev_dec, max));
      EXPECT_EQ(reconstruct(dec_g, max), reconstruct(want, max));
      EXPECT_EQ(dec_g.shift, want.shift);
    }
    EXPECT_FALSE(dec.exhausted_badly());
  }
}

TEST(EmbeddedGeometry, HostileBitsNeverLeaveTheGrid) {
  std::mt19937 rng(8);
  for (int trial = 0; trial < 500; ++trial) {
    std::vector<uint8_t> junk(64);
    for (auto& b : junk) b = uint8_t(rng());
    RangeDecoder dec(junk);
    PlaneBitReader io{dec};
    GeometryModels m;
    VertexGeometry g;
    g.anchor = {int32_t(rng() % 4096), int32_t(rng() % 4096), int32_t(rng() % 4096)};
    g.shift = uint8_t(1 + rng() % 12);
    g.normal_axis = uint8_t(rng() % 4);
    uint8_t prev = 0;
    while (g.shift > 0) {
      if (!plane_step(m, io, g, prev, 4095)) break;  // refused: a magnitude beyond the grid
      const Vec3i p = reconstruct(g, 4095);
      for (int a = 0; a < 3; ++a) {
        EXPECT_GE(p[a], 0);
        EXPECT_LE(p[a], 4095);
      }
    }
  }
}

// A stream written by issue I's encoder (container 1, 24-byte index entries,
// refinement format 1, Draco base): still decodes completely.
TEST(EmbeddedGeometry, IssueOneStreamsStillDecode) {
  for (const char* name : {"components3_draco.hcs", "components3_own.hcs", "grid8_draco.hcs"}) {
    const std::string path = std::string(MESHSTREAM_SOURCE_DIR) + "/tests/fuzz/corpus/hcs_decoder/" + name;
    std::ifstream in(path, std::ios::binary);
    ASSERT_TRUE(in) << path;
    const std::vector<uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    auto index = read_stream_index(bytes);
    ASSERT_TRUE(index) << index.error().message;
    ASSERT_EQ(index->header.extra.at(0), 1) << "the corpus file is of format 1";
    IncrementalDecoder dec;
    auto r = dec.feed(bytes);
    ASSERT_TRUE(r) << name << ": " << r.error().message;
    EXPECT_TRUE(dec.finished());
    EXPECT_EQ(dec.mesh().vertex_count(), index->header.vertex_count);
  }
}

}  // namespace
}  // namespace meshstream
