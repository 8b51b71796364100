// Conforming closure, hand-made: one targeted neighbour bisects, two make a
// target, targets propagate, and a green half is never bisected again (its
// pair is merged back and the parent split 1-to-4). Works on the internal
// level structures so that targets can be chosen exactly.
#include "common/asa/butterfly_stencils.h"
#include "common/asa/closure.h"
#include "common/asa/flatness.h"
#include "common/asa/split.h"
#include "tests/asa/asa_test_support.h"

namespace meshstream {
namespace {

using namespace asa;

// Level-0 structures of a mesh, the way subdivide builds them.
struct Level {
  Mesh mesh;
  LevelMesh lm;
  ButterflyWeights weights;
  explicit Level(Mesh m) : mesh(std::move(m)) {
    lm = asa_test::level_with_opposites(mesh);
    finish();
  }
  explicit Level(LevelMesh next) : lm(std::move(next)) {
    mesh.positions = lm.positions;
    mesh.triangles = lm.triangles;
    LevelView v = lm.view();
    count_vertex_faces(v, lm.valence);
    weights.configure(0);
    weights.add_valences(lm.valence.data(), lm.vertex_features.data(),
                         static_cast<uint32_t>(lm.valence.size()));
  }
  void finish() {
    std::vector<Vec3f> normals;
    LevelView v = lm.view();
    compute_face_normals(v, normals);
    tag_feature_edges(v, 0, normals, lm.feature_edge);
    v = lm.view();
    count_vertex_features(v, lm.vertex_features);
    count_vertex_faces(v, lm.valence);
    weights.configure(0);
    weights.add_valences(lm.valence.data(), lm.vertex_features.data(),
                         static_cast<uint32_t>(lm.valence.size()));
  }
  // Splits with the given closure; returns the next level.
  LevelMesh split(const ClosureBuffers& closure) {
    SplitInput in;
    in.mesh = lm.view();
    in.weights = &weights;
    SplitScratch scratch;
    LevelMesh out;
    split_adaptive(in, closure, scratch, out, nullptr);
    return out;
  }
};

int count_action(const ClosureBuffers& b, FaceAction a) {
  int n = 0;
  for (uint8_t x : b.action) n += x == a;
  return n;
}

// The derived corner table must equal the one built from scratch.
// `across` is kept by the uniform split only (adaptive levels drop it).
void expect_topology_consistent(const LevelMesh& out, bool with_across = false) {
  Mesh m;
  m.positions = out.positions;
  m.triangles = out.triangles;
  auto adj = Adjacency::build(m);
  ASSERT_TRUE(adj.has_value()) << adj.error().message;
  ASSERT_EQ(out.opposite.size(), 3 * m.triangles.size());
  for (uint32_t c = 0; c < out.opposite.size(); ++c)
    ASSERT_EQ(out.opposite[c], adj->opposite(c)) << c;
  for (uint32_t c = 0; c < out.opposite.size(); ++c)
    ASSERT_EQ(out.feature_edge[c] != 0, adj->opposite(c) == kNone) << c;
  // across (vertex of the opposite corner), derived by the split as well.
  if (!with_across) {
    EXPECT_TRUE(out.across.empty());
    return;
  }
  ASSERT_EQ(out.across.size(), out.opposite.size());
  for (uint32_t c = 0; c < out.across.size(); ++c)
    ASSERT_EQ(out.across[c], adj->opposite(c) == kNone
                                 ? kNone
                                 : m.triangles[adj->opposite(c) / 3][adj->opposite(c) % 3])
        << c;
}

// In the grid, face 2 * (j * n + i) is the lower triangle of square (i, j).
uint32_t lower(int n, int i, int j) { return static_cast<uint32_t>(2 * (j * n + i)); }

TEST(AsaClosure, OneTargetBisectsItsThreeNeighbours) {
  Level L(asa_test::flat_grid(4));
  std::vector<uint8_t> target(L.mesh.face_count(), 0);
  const uint32_t t = lower(4, 1, 1);
  target[t] = 1;
  ClosureBuffers b;
  EXPECT_EQ(close_targets(L.lm.view(), target.data(), b), 3u);
  EXPECT_EQ(b.action[t], kRed);
  EXPECT_EQ(count_action(b, kRed), 1);
  EXPECT_EQ(count_action(b, kBisect), 3);
  for (uint32_t n :
       {L.lm.opposite[3 * t] / 3, L.lm.opposite[3 * t + 1] / 3, L.lm.opposite[3 * t + 2] / 3})
    EXPECT_EQ(b.action[n], kBisect);
  LevelMesh out = L.split(b);
  EXPECT_EQ(out.triangles.size(), L.mesh.face_count() + 3 + 3);
  expect_topology_consistent(out);
}

TEST(AsaClosure, TwoTargetedNeighboursMakeATargetAndPropagate) {
  Level L(asa_test::flat_grid(4));
  // The upper triangle of square (1,1) has neighbours: lower(1,1) (across the
  // diagonal), lower(1,2) (above) and lower(0,1)... choose two of them.
  const uint32_t middle = lower(4, 1, 1) + 1;
  std::vector<uint32_t> nbr;
  for (uint32_t i = 0; i < 3; ++i) nbr.push_back(L.lm.opposite[3 * middle + i] / 3);
  std::vector<uint8_t> target(L.mesh.face_count(), 0);
  target[nbr[0]] = target[nbr[1]] = 1;
  ClosureBuffers b;
  close_targets(L.lm.view(), target.data(), b);
  EXPECT_EQ(b.action[middle], kRed) << "two split edges make a target";
  // Its third edge is now split: the third neighbour gets at least a bisection.
  EXPECT_NE(b.action[nbr[2]], kKeep);
  for (uint32_t c = 0; c < 3; ++c) EXPECT_TRUE(b.edge_split[3 * middle + c]);
  // Every face ends with 0, 1 (bisect) or 3 (red) split edges.
  for (uint32_t f = 0; f < L.mesh.face_count(); ++f) {
    const int k = b.edge_split[3 * f] + b.edge_split[3 * f + 1] + b.edge_split[3 * f + 2];
    if (b.action[f] == kRed) {
      EXPECT_EQ(k, 3);
    } else if (b.action[f] == kBisect) {
      EXPECT_EQ(k, 1);
    } else {
      EXPECT_EQ(k, 0);
    }
  }
  expect_topology_consistent(L.split(b));
}

// A row of targets in a strip: closure must reach a fixed point where no
// face is left with two split edges.
TEST(AsaClosure, PropagationReachesAFixedPoint) {
  Level L(asa_test::flat_grid(8));
  std::vector<uint8_t> target(L.mesh.face_count(), 0);
  for (int i = 0; i < 8; i += 2) target[lower(8, i, 3)] = 1;
  for (int j = 0; j < 8; j += 3) target[lower(8, 5, j) + 1] = 1;
  ClosureBuffers b;
  close_targets(L.lm.view(), target.data(), b);
  for (uint32_t f = 0; f < L.mesh.face_count(); ++f) {
    const int k = b.edge_split[3 * f] + b.edge_split[3 * f + 1] + b.edge_split[3 * f + 2];
    EXPECT_TRUE(k == 0 || k == 1 || k == 3) << "face " << f << " has " << k << " split edges";
    if (target[f]) {
      EXPECT_EQ(b.action[f], kRed);
    }
  }
  expect_topology_consistent(L.split(b));
}

// Red-green: at the next level a green half that is a target, or that has
// a split outer edge, is not bisected: the pair opens and its parent is
// split 1-to-4 reusing the existing midpoint.
TEST(AsaClosure, GreenHalfIsNeverBisectedAgain) {
  Level L0(asa_test::flat_grid(4));
  std::vector<uint8_t> target(L0.mesh.face_count(), 0);
  target[lower(4, 1, 1)] = 1;
  ClosureBuffers b0;
  close_targets(L0.lm.view(), target.data(), b0);
  LevelMesh level1 = L0.split(b0);
  expect_topology_consistent(level1);
  Level L1(std::move(level1));
  // Find a green pair.
  uint32_t first = kNone;
  for (uint32_t f = 0; f < L1.lm.green.size(); ++f)
    if (L1.lm.green[f] == kGreenFirst) {
      first = f;
      break;
    }
  ASSERT_NE(first, kNone);
  const uint32_t M = L1.lm.triangles[first][2];
  const size_t vertices_before = L1.lm.positions.size();

  // Case 1: the green half itself is a target.
  {
    std::vector<uint8_t> t1(L1.lm.triangles.size(), 0);
    t1[first + 1] = 1;
    ClosureBuffers b1;
    close_targets(L1.lm.view(), t1.data(), b1);
    EXPECT_EQ(b1.action[first], kOpened);
    EXPECT_EQ(b1.action[first + 1], kOpened);
    for (uint32_t f = 0; f < L1.lm.green.size(); ++f)
      if (L1.lm.green[f] != kNotGreen) {
        EXPECT_NE(b1.action[f], kBisect) << "green face " << f << " bisected";
      }
    LevelMesh level2 = L1.split(b1);
    expect_topology_consistent(level2);
    // The parent's split reuses M: no new vertex lies on the old edge B-C
    // besides it, and M is used by the parent's children.
    int uses_of_m = 0;
    for (const Triangle& t : level2.triangles) uses_of_m += (t[0] == M || t[1] == M || t[2] == M);
    EXPECT_GE(uses_of_m, 4);
    EXPECT_GT(level2.positions.size(), vertices_before);
  }
  // Case 2: the face across the pair's outer edge A-B is a target: the half
  // would need a bisection, so the pair opens instead.
  {
    const uint32_t across_ab = L1.lm.opposite[3 * first + 2];
    ASSERT_NE(across_ab, kNone);
    std::vector<uint8_t> t2(L1.lm.triangles.size(), 0);
    t2[across_ab / 3] = 1;
    ClosureBuffers b2;
    close_targets(L1.lm.view(), t2.data(), b2);
    if (L1.lm.green[across_ab / 3] == kNotGreen) {
      EXPECT_EQ(b2.action[first], kOpened);
      EXPECT_EQ(b2.action[first + 1], kOpened);
    }
    for (uint32_t f = 0; f < L1.lm.green.size(); ++f)
      if (L1.lm.green[f] != kNotGreen) {
        EXPECT_NE(b2.action[f], kBisect);
      }
    expect_topology_consistent(L1.split(b2));
  }
}

TEST(AsaClosure, UniformSplitDerivesTheCornerTable) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  Level L(asa_test::load("hemisphere.off"));
  SplitInput in;
  in.mesh = L.lm.view();
  in.weights = &L.weights;
  SplitScratch scratch;
  LevelMesh out;
  split_uniform(in, scratch, out, nullptr);
  expect_topology_consistent(out, /*with_across=*/true);
}

}  // namespace
}  // namespace meshstream
