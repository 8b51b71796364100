// The fast edge-point passes (regular stencils through `across`, every
// extraordinary centre's stencils from one gathered ring, fans cached across
// uniform levels) give exactly the bits of the per-edge reference
// butterfly_point on the level they subdivide.
#include <cstring>

#include "common/asa/butterfly_stencils.h"
#include "common/asa/flatness.h"
#include "common/asa/level_mesh.h"
#include "tests/asa/asa_test_support.h"

namespace meshstream {
namespace {

using namespace asa;

// Level-0 structures of `mesh` (no creases), built independently of subdivide.
struct Reference {
  Mesh mesh;
  LevelMesh lm;
  ButterflyWeights weights;
  explicit Reference(const Mesh& m, float tension) : mesh(m) {
    lm = asa_test::level_with_opposites(mesh);
    std::vector<Vec3f> normals;
    LevelView v = lm.view();
    tag_feature_edges(v, 0, normals, lm.feature_edge);
    v = lm.view();
    count_vertex_features(v, lm.vertex_features);
    count_vertex_faces(v, lm.valence);
    weights.configure(tension);
    weights.add_valences(lm.valence.data(), lm.vertex_features.data(),
                         static_cast<uint32_t>(lm.valence.size()));
  }
};

// Uniform level n's new vertices, in naming order (the first corner of each
// edge in corner order), against butterfly_point on level n - 1.
void expect_uniform_level_matches_reference(const Mesh& input, int level, ButterflyRule rule,
                                            float tension, const char* what) {
  AsaOptions o;
  o.uniform = true;
  o.rule = rule;
  o.tension = tension;
  o.levels = level - 1;
  auto before = subdivide(input, o);
  o.levels = level;
  auto after = subdivide(input, o);
  ASSERT_TRUE(before.has_value() && after.has_value()) << what;
  Reference ref(before->mesh, tension);
  const LevelView v = ref.lm.view();
  const EdgePlacement placement =
      rule == ButterflyRule::kProjection ? EdgePlacement::kProjection : EdgePlacement::kZorin;
  uint32_t id = v.vertex_count, checked = 0;
  for (uint32_t c = 0; c < 3 * v.face_count; ++c) {
    const uint32_t o = v.opposite[c];
    if (o != kNone && o < c) continue;
    const Vec3f expected = butterfly_point(v, c, ref.weights, placement);
    ASSERT_LT(id, after->mesh.vertex_count()) << what;
    const Vec3f got = after->mesh.positions[id++];
    ASSERT_EQ(std::memcmp(&expected, &got, sizeof(Vec3f)), 0)
        << what << " level " << level << " corner " << c << ": " << got.x << " " << got.y << " "
        << got.z << " vs " << expected.x << " " << expected.y << " " << expected.z;
    ++checked;
  }
  EXPECT_EQ(id, after->mesh.vertex_count()) << what;
  EXPECT_GT(checked, 0u) << what;
}

TEST(AsaEdgePoints, UniformLevelsMatchThePerEdgeStencilsBitForBit) {
  const Mesh ico = asa_test::icosahedron();
  for (int level = 1; level <= 3; ++level) {
    expect_uniform_level_matches_reference(ico, level, ButterflyRule::kZorin, 0, "icosahedron");
    expect_uniform_level_matches_reference(ico, level, ButterflyRule::kProjection, 0,
                                           "icosahedron projection");
    expect_uniform_level_matches_reference(ico, level, ButterflyRule::kZorin, 0.05f,
                                           "icosahedron tension");
  }
}

TEST(AsaEdgePoints, RealMeshesMatchThePerEdgeStencilsBitForBit) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  // Irregular scans, valence-3 to high-valence fans, a mesh with boundaries.
  for (const char* name : {"bunny.off", "hemisphere.off", "fandisk.off"}) {
    const Mesh m = asa_test::load(name);
    for (int level = 1; level <= 2; ++level) {
      expect_uniform_level_matches_reference(m, level, ButterflyRule::kZorin, 0, name);
    }
    expect_uniform_level_matches_reference(m, 1, ButterflyRule::kProjection, 0, name);
  }
}

}  // namespace
}  // namespace meshstream
