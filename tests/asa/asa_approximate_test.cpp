// The approximating post-processing (approximate.h): relaxing a noisy
// coarse mesh brings it closer to the smooth surface it samples, keeps a
// closed surface's size (Taubin's lambda|mu, not plain Laplacian
// shrinking), and leaves flat regions, sharp edges and boundaries alone.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/asa/approximate.h"
#include "common/asa/subdivide.h"
#include "common/mesh/procedural.h"

namespace meshstream {
namespace {

// RMS of |p| - 1 over the vertices: the distance of a unit sphere's samples
// from the sphere itself.
double sphere_rms(const Mesh& m) {
  double sum = 0;
  for (const Vec3f& p : m.positions) {
    const double d = double(length(p)) - 1.0;
    sum += d * d;
  }
  return std::sqrt(sum / double(m.vertex_count()));
}

double mean_radius(const Mesh& m) {
  double sum = 0;
  for (const Vec3f& p : m.positions) sum += double(length(p));
  return sum / double(m.vertex_count());
}

// A coarse unit sphere whose vertices carry radial errors of about 2 % of
// the radius (a coarse prefix's decoded positions off the surface).
Mesh noisy_sphere(uint32_t subdivisions, float amplitude, uint32_t seed) {
  Mesh m = make_icosphere(subdivisions);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> noise(-amplitude, amplitude);
  for (Vec3f& p : m.positions) p = p * (1.0f + noise(rng));
  return m;
}

TEST(Approximate, RelaxingANoisySphereBringsItCloserToTheSphere) {
  for (uint32_t seed : {1u, 2u, 3u}) {
    const Mesh noisy = noisy_sphere(3, 0.02f, seed);  // 1280 faces
    Mesh relaxed = noisy;
    ASSERT_TRUE(relax_toward_smooth(relaxed));
    const double before = sphere_rms(noisy), after = sphere_rms(relaxed);
    EXPECT_LT(after, 0.85 * before) << "seed " << seed;
    // Not by shrinking: the mean radius stays within 0.5 % of the sphere's.
    EXPECT_NEAR(mean_radius(relaxed), 1.0, 0.005);
    EXPECT_EQ(relaxed.triangles, noisy.triangles);
  }
}

TEST(Approximate, RelaxedThenSplitIsCloserThanInterpolatingTheErrors) {
  // ASA interpolates the noisy positions; relaxing them first (what an
  // approximating guidance choice does, apply_asa_choice) does not, and
  // beats relaxing ASA's output.
  const Mesh noisy = noisy_sphere(2, 0.03f, 7);  // 320 faces
  AsaOptions o;
  o.uniform = true;
  auto split = subdivide(noisy, o);
  ASSERT_TRUE(split);
  Mesh relaxed = noisy;
  ASSERT_TRUE(relax_toward_smooth(relaxed));
  auto relaxed_split = subdivide(relaxed, o);
  ASSERT_TRUE(relaxed_split);
  Mesh split_relaxed = split->mesh;
  ASSERT_TRUE(relax_toward_smooth(split_relaxed));
  EXPECT_LT(sphere_rms(relaxed_split->mesh), 0.85 * sphere_rms(split->mesh));
  EXPECT_LT(sphere_rms(relaxed_split->mesh), sphere_rms(split_relaxed));
}

TEST(Approximate, ASmoothSphereMovesLittle) {
  // Nothing to remove: a clean icosphere's vertices move by far less than
  // the noise above (the filter passes the sphere's low frequency).
  const Mesh clean = make_icosphere(3);
  Mesh relaxed = clean;
  ASSERT_TRUE(relax_toward_smooth(relaxed));
  EXPECT_LT(sphere_rms(relaxed), 0.002);
}

TEST(Approximate, FlatRegionsSharpEdgesAndBoundariesStayPut) {
  // A cube: its faces are flat (no normal part to remove) and its edges
  // sharp (90 degrees > 60): nothing moves, bit for bit.
  const Mesh cube = make_faceted_cube(4);
  Mesh relaxed = cube;
  ASSERT_TRUE(relax_toward_smooth(relaxed));
  EXPECT_EQ(relaxed.positions, cube.positions);
  // An open grid with a bumped interior: the boundary stays fixed, the bump
  // is flattened.
  Mesh grid = make_open_grid(8);
  for (Vec3f& p : grid.positions) p.z = 0;  // flat (the grid is waved in z)
  const uint32_t middle = grid.vertex_count() / 2;
  std::vector<uint8_t> on_boundary(grid.vertex_count(), 0);
  {
    std::vector<std::pair<uint32_t, uint32_t>> edges;
    for (const Triangle& t : grid.triangles)
      for (int k = 0; k < 3; ++k)
        edges.push_back({std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])});
    std::sort(edges.begin(), edges.end());
    for (size_t i = 0; i < edges.size(); ++i) {
      const bool single = (i == 0 || edges[i - 1] != edges[i]) &&
                          (i + 1 == edges.size() || edges[i + 1] != edges[i]);
      if (single) on_boundary[edges[i].first] = on_boundary[edges[i].second] = 1;
    }
  }
  ASSERT_FALSE(on_boundary[middle]);
  const Vec3f normal{0, 0, 1};
  const float spacing =
      length(grid.positions[grid.triangles[0][1]] - grid.positions[grid.triangles[0][0]]);
  grid.positions[middle] = grid.positions[middle] + normal * (0.3f * spacing);
  Mesh bumped = grid;
  ASSERT_TRUE(relax_toward_smooth(bumped));
  for (uint32_t v = 0; v < grid.vertex_count(); ++v)
    if (on_boundary[v]) {
      EXPECT_EQ(bumped.positions[v], grid.positions[v]) << v;
    }
  const auto height = [&](const Mesh& m) {
    return std::abs(dot(m.positions[middle] - grid.positions[0], normal));
  };
  EXPECT_LT(height(bumped), 0.8f * height(grid));
}

TEST(Approximate, BadOptionsAndBrokenMeshesAreRefused) {
  Mesh m = make_icosphere(1);
  RelaxOptions o;
  o.mu = -0.2f;  // |mu| < lambda would shrink
  EXPECT_EQ(relax_toward_smooth(m, o).error().code, ErrorCode::kInvalidArgument);
  o = {};
  o.iterations = -1;
  EXPECT_FALSE(relax_toward_smooth(m, o));
  Mesh broken = m;
  broken.triangles[0][0] = broken.vertex_count() + 5;
  EXPECT_FALSE(relax_toward_smooth(broken));
  o = {};
  o.iterations = 0;
  Mesh same = m;
  ASSERT_TRUE(relax_toward_smooth(same, o));
  EXPECT_EQ(same.positions, m.positions);
}

}  // namespace
}  // namespace meshstream
