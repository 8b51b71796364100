// FrameMeshPool: every mesh it gives out equals the mirror at that moment,
// a mesh someone still holds is never written, and a free mesh is brought up
// to date from the changes only (no whole copy per display update).
#include "client/frame_mesh_pool.h"

#include <gtest/gtest.h>

#include <deque>
#include <random>

namespace meshstream::client {
namespace {

// A mirror that changes the way a decoded stream does: vertices and faces
// appended, faces rewritten, vertices moved, now and then a full rebuild.
struct ChangingMirror {
  Mesh mesh;
  std::mt19937 rng{7};

  MeshChanges rebuild(uint32_t vertices, uint32_t faces) {
    mesh = Mesh{};
    for (uint32_t v = 0; v < vertices; ++v) mesh.positions.push_back(random_point());
    for (uint32_t f = 0; f < faces; ++f) mesh.triangles.push_back(random_face());
    MeshChanges c;
    c.full = true;
    return c;
  }

  MeshChanges step() {
    MeshChanges c;
    const uint32_t added = rng() % 5;
    for (uint32_t i = 0; i < added; ++i) {
      c.vertices.push_back(static_cast<uint32_t>(mesh.positions.size()));
      mesh.positions.push_back(random_point());
      c.faces.push_back(static_cast<uint32_t>(mesh.triangles.size()));
      mesh.triangles.push_back(random_face());
    }
    for (uint32_t i = rng() % 4; i > 0; --i) {
      const uint32_t f = rng() % mesh.triangles.size();
      mesh.triangles[f] = random_face();
      c.faces.push_back(f);
    }
    for (uint32_t i = rng() % 3; i > 0; --i) {
      const uint32_t v = rng() % mesh.positions.size();
      mesh.positions[v] = random_point();
      c.moved.push_back(v);
    }
    return c;
  }

  Vec3f random_point() { return {float(rng() % 1000), float(rng() % 1000), float(rng() % 1000)}; }
  Triangle random_face() {
    const uint32_t n = static_cast<uint32_t>(std::max<size_t>(mesh.positions.size(), 1));
    return {uint32_t(rng() % n), uint32_t(rng() % n), uint32_t(rng() % n)};
  }
};

void expect_equal(const Mesh& got, const Mesh& want, int step) {
  ASSERT_EQ(got.positions, want.positions) << "step " << step;
  ASSERT_EQ(got.triangles, want.triangles) << "step " << step;
}

TEST(FrameMeshPool, EveryMeshEqualsTheMirrorAndHeldMeshesNeverChange) {
  ChangingMirror mirror;
  FrameMeshPool pool;
  // Meshes consumers still hold, with what they held when given out.
  std::deque<std::pair<std::shared_ptr<const Mesh>, Mesh>> held;
  std::mt19937 rng(11);
  MeshChanges changes = mirror.rebuild(50, 80);
  for (int step = 0; step < 3000; ++step) {
    auto mesh = pool.share(mirror.mesh, changes);
    expect_equal(*mesh, mirror.mesh, step);
    // Consumers keep 0 to 6 frames, released in any order.
    if (rng() % 3 != 0) held.emplace_back(mesh, *mesh);
    while (held.size() > rng() % 7) held.erase(held.begin() + rng() % held.size());
    for (const auto& [kept, snapshot] : held) expect_equal(*kept, snapshot, step);
    changes = step % 700 == 699 ? mirror.rebuild(40 + step % 13, 70) : mirror.step();
  }
  // Most updates reused a free mesh by its changes alone.
  EXPECT_GT(pool.stats().updates, 1500u);
  EXPECT_LT(pool.stats().whole_copies, 1500u);
}

// The display pipeline's steady state (the mailbox and the viewer hold the
// last two frames): one whole copy per kept mesh at the start, then only
// changes.
TEST(FrameMeshPool, CopiesOnlyTheChangesOnceMeshesAreFree) {
  ChangingMirror mirror;
  FrameMeshPool pool;
  MeshChanges changes = mirror.rebuild(1000, 2000);
  std::deque<std::shared_ptr<const Mesh>> held;
  for (int step = 0; step < 200; ++step) {
    held.push_back(pool.share(mirror.mesh, changes));
    expect_equal(*held.back(), mirror.mesh, step);
    if (held.size() > 2) held.pop_front();
    changes = mirror.step();
  }
  EXPECT_EQ(pool.stats().whole_copies, 3u);  // the first three meshes
  EXPECT_EQ(pool.stats().updates, 197u);
}

// A full change (a new base mesh) reaches every kept mesh: reused ones are
// copied whole once.
TEST(FrameMeshPool, AFullChangeReachesEveryKeptMesh) {
  ChangingMirror mirror;
  FrameMeshPool pool;
  MeshChanges changes = mirror.rebuild(20, 30);
  auto a = pool.share(mirror.mesh, changes);
  auto b = pool.share(mirror.mesh, mirror.step());
  a.reset();
  b.reset();
  changes = mirror.rebuild(60, 90);
  auto c = pool.share(mirror.mesh, changes);
  expect_equal(*c, mirror.mesh, 0);
  auto d = pool.share(mirror.mesh, mirror.step());
  expect_equal(*d, mirror.mesh, 1);
  EXPECT_EQ(pool.stats().whole_copies, 4u);
  EXPECT_EQ(pool.stats().updates, 0u);
}

}  // namespace
}  // namespace meshstream::client
