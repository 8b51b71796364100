// The surface-error cache of the distortion estimate (EncoderTruth::cached):
// whatever it keeps or drops, every answer is the exact closest-point
// query's, for positions near the truth (cached as offsets) and far from
// it (beyond the offsets' 10 bits an axis: searched every time).
#include "common/codec/distortion_estimate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <random>

#include "common/mesh/procedural.h"
#include "common/metrics/bvh.h"

namespace meshstream {
namespace {

TEST(SurfaceErrorCache, EveryAnswerIsTheExactQuerys) {
  // A sphere in grid units (radius 1500 around 2048), its hierarchy.
  const Mesh sphere = make_icosphere(3);
  std::vector<Vec3i> q;
  Mesh grid;
  grid.triangles = sphere.triangles;
  for (const Vec3f& p : sphere.positions) {
    const Vec3i g{int(std::lround(2048 + 1500 * p.x)), int(std::lround(2048 + 1500 * p.y)),
                  int(std::lround(2048 + 1500 * p.z))};
    q.push_back(g);
    grid.positions.push_back(vec3_cast<float>(g));
  }
  const TriangleBvh surface = TriangleBvh::build(grid);
  EncoderTruth truth;
  truth.input_position = q;
  truth.surface = &surface;
  for (uint32_t v = 0; v < q.size(); ++v) truth.input_of.push_back(uint32_t(q.size()) - 1 - v);

  std::mt19937 rng(3);
  std::uniform_int_distribution<int> near(-600, 600), pick(0, int(q.size()) - 1);
  std::uniform_int_distribution<int> kind(0, 3);
  uint64_t far = 0;
  // Positions of a few vertices asked again and again (as plane groups are
  // evaluated again), new ones in between, some beyond the offsets' reach.
  std::vector<Vec3i> last(q.size());
  for (int i = 0; i < 20000; ++i) {
    const uint32_t v = uint32_t(pick(rng)) % 64;
    const Vec3i t = truth.position(v);
    Vec3i recon;
    switch (kind(rng)) {
      case 0:
        recon = last[v];
        break;
      case 1:
        recon = t + Vec3i{near(rng) / 8, near(rng) / 8, near(rng) / 8};
        break;
      case 2:
        recon = t + Vec3i{near(rng), near(rng), near(rng)};
        break;
      default:
        recon = t;
        break;
    }
    last[v] = recon;
    const double want = recon == t ? 0.0 : surface.closest(to_double(recon)).squared_distance;
    ASSERT_EQ(vertex_error2(truth, v, recon), want) << i;
    for (int a = 0; a < 3; ++a) far += std::abs(recon[a] - t[a]) >= 512;
  }
  EXPECT_GT(far, 100u);  // the far positions were asked about
  EXPECT_EQ(truth.cached.size(), 64u);
}

}  // namespace
}  // namespace meshstream
