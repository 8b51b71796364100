// Surface distances on the real meshes of ../shared/meshes (skipped when absent).
#include <gtest/gtest.h>

#include "common/mesh/import.h"
#include "common/metrics/distance.h"
#include "tests/test_meshes.h"

namespace meshstream {
namespace {

Mesh load(const std::string& name) {
  auto imported = import_mesh(testing::test_mesh(name));
  EXPECT_TRUE(imported) << imported.error().message;
  return imported ? imported->mesh : Mesh{};
}

// bun_zipper is the scan; bunny.off is the same scan with its five holes
// filled. Every point of the scan lies on the filled bunny, but the patches
// over the holes are away from the scan.
TEST(RealMeshDistance, FilledBunnyContainsTheScanButNotTheReverse) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  const Mesh filled = load("bunny.off");
  const Mesh scan = load("bun_zipper.ply");
  DistanceOptions options;
  options.samples = 50000;
  auto d = surface_distance(filled, scan, options);
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_LT(d->b_to_a.max, 1e-5 * d->diagonal);  // the scan lies on the filled surface
  EXPECT_GT(d->a_to_b.max, 1e-2 * d->diagonal);  // the hole patches do not lie on the scan
  EXPECT_EQ(d->hausdorff, d->a_to_b.max);
}

TEST(RealMeshDistance, PreparedOriginalAgainstManyCandidatesIsDeterministic) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  const Mesh fandisk = load("fandisk.off");
  Mesh moved = fandisk;
  for (Vec3f& p : moved.positions) p.x += 0.001f;
  DistanceOptions options;
  options.samples = 20000;
  options.threads = 2;
  auto original = PreparedSurface::prepare(fandisk, options);
  auto candidate = PreparedSurface::prepare(moved, options);
  ASSERT_TRUE(original && candidate);
  const SurfaceDistance first = surface_distance(*original, *candidate);
  const SurfaceDistance again = surface_distance(*original, *candidate);
  EXPECT_EQ(first.hausdorff, again.hausdorff);
  EXPECT_EQ(first.rms, again.rms);
  // A translation by t moves no point farther than t.
  EXPECT_LE(first.hausdorff, 0.001 + 1e-6);
  EXPECT_GT(first.rms, 0.0);
}

}  // namespace
}  // namespace meshstream
