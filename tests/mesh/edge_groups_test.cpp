// update_edge_groups must give exactly what build_edge_groups gives on the
// changed mesh: the repair's rounds rely on it instead of building the
// groups again, and the imported mesh depends on the groups' order.
#include "common/mesh/edge_groups.h"

#include <gtest/gtest.h>

#include <random>

#include "common/mesh/corner_data.h"
#include "common/mesh/procedural.h"

namespace meshstream {
namespace {

void expect_same_groups(const EdgeGroups& got, const EdgeGroups& want) {
  ASSERT_EQ(got.edge_count(), want.edge_count());
  EXPECT_EQ(got.lo, want.lo);
  EXPECT_EQ(got.hi, want.hi);
  EXPECT_EQ(got.begin, want.begin);
  ASSERT_EQ(got.uses.size(), want.uses.size());
  for (size_t k = 0; k < got.uses.size(); ++k) {
    ASSERT_EQ(got.uses[k].face, want.uses[k].face) << "use " << k;
    ASSERT_EQ(got.uses[k].local, want.uses[k].local) << "use " << k;
    ASSERT_EQ(got.uses[k].forward, want.uses[k].forward) << "use " << k;
  }
}

// Changes about `share` of the faces as the repair does (a corner moved to a
// new copy of its vertex, or to another face's vertex, so edges appear,
// merge and vanish; faces reversed), updates the groups and compares them
// with a fresh build, for several rounds on the same groups.
void check_random_changes(Mesh mesh, double share, uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  EdgeGroups groups = build_edge_groups(mesh);
  for (int round = 0; round < 4; ++round) {
    std::vector<uint8_t> change(mesh.face_count(), kFaceKept);
    std::vector<std::pair<uint32_t, Triangle>> old_triangles;
    for (uint32_t f = 0; f < mesh.face_count(); ++f) {
      if (unit(random) >= share) continue;
      const double what = unit(random);
      Triangle& t = mesh.triangles[f];
      if (what < 0.3) {
        reverse_face(mesh, f);
        change[f] |= kFaceReversed;
        continue;
      }
      const uint32_t i = random() % 3;
      uint32_t v;
      if (what < 0.7) {
        v = mesh.vertex_count();
        mesh.positions.push_back(mesh.positions[t[i]]);
      } else {
        v = random() % mesh.vertex_count();
        if (v == t[0] || v == t[1] || v == t[2]) continue;
      }
      old_triangles.emplace_back(f, t);
      t[i] = v;
      change[f] |= kFaceRenumbered;
      if (what > 0.9) {
        reverse_face(mesh, f);
        change[f] |= kFaceReversed;
      }
    }
    update_edge_groups(groups, mesh, change, old_triangles);
    expect_same_groups(groups, build_edge_groups(mesh));
    if (::testing::Test::HasFailure()) return;
  }
}

TEST(EdgeGroupsUpdate, NoChangeKeepsTheGroups) {
  Mesh mesh = make_icosphere(2);
  EdgeGroups groups = build_edge_groups(mesh);
  update_edge_groups(groups, mesh, std::vector<uint8_t>(mesh.face_count(), kFaceKept), {});
  expect_same_groups(groups, build_edge_groups(mesh));
}

TEST(EdgeGroupsUpdate, FewChangesEqualAFreshBuild) {
  for (uint32_t seed = 1; seed <= 8; ++seed) check_random_changes(make_icosphere(3), 0.01, seed);
}

TEST(EdgeGroupsUpdate, ManyChangesEqualAFreshBuild) {
  for (uint32_t seed = 1; seed <= 4; ++seed) check_random_changes(make_torus(24, 12), 0.3, seed);
  check_random_changes(make_open_grid(20), 1.0, 9);
}

TEST(EdgeGroupsUpdate, FirstAndLastFacesRenumbered) {
  Mesh mesh = make_open_grid(8);
  EdgeGroups groups = build_edge_groups(mesh);
  std::vector<uint8_t> change(mesh.face_count(), kFaceKept);
  std::vector<std::pair<uint32_t, Triangle>> old_triangles;
  for (uint32_t f : {0u, mesh.face_count() - 1}) {
    old_triangles.emplace_back(f, mesh.triangles[f]);
    mesh.positions.push_back(mesh.positions[mesh.triangles[f][0]]);
    mesh.triangles[f][0] = mesh.vertex_count() - 1;
    change[f] = kFaceRenumbered;
  }
  update_edge_groups(groups, mesh, change, old_triangles);
  expect_same_groups(groups, build_edge_groups(mesh));
}

TEST(EdgeGroupsUpdate, AMissingOldTriangleStillGivesAFreshBuildsGroups) {
  Mesh mesh = make_icosphere(2);
  EdgeGroups groups = build_edge_groups(mesh);
  std::vector<uint8_t> change(mesh.face_count(), kFaceKept);
  mesh.positions.push_back(mesh.positions[mesh.triangles[5][1]]);
  mesh.triangles[5][1] = mesh.vertex_count() - 1;
  change[5] = kFaceRenumbered;
  update_edge_groups(groups, mesh, change, {});  // face 5's old triangle not given
  expect_same_groups(groups, build_edge_groups(mesh));
}

}  // namespace
}  // namespace meshstream
