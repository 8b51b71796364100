// The two local edits of the codec are exact inverses and keep the corner
// table identical to one built from scratch.
#include "common/codec/editable_mesh.h"

#include <gtest/gtest.h>

#include <random>

#include "common/codec/base_coder.h"
#include "common/codec/decimate.h"
#include "common/codec/encoder.h"
#include "common/codec/quantize.h"
#include "common/codec/refinement_codec.h"
#include "tests/codec/codec_test_util.h"

namespace meshstream {
namespace {

using namespace meshstream::testing;

// Rebuilding from the live faces must give a valid manifold mesh.
void expect_manifold(const EditableMesh& m) {
  Mesh plain;
  plain.positions.resize(m.vertex_count());
  plain.triangles = m.live_faces();
  auto adj = Adjacency::build(plain);
  ASSERT_TRUE(adj) << adj.error().message;
}

TEST(EditableMesh, RemoveThenInsertRestoresTheStar) {
  for (const Mesh& input : {icosphere(2, 0.1f), height_field(8, 7)}) {
    auto grid = make_grid(input, 12);
    ASSERT_TRUE(grid);
    auto m = EditableMesh::build(quantize_positions(input, *grid), input.triangles);
    ASSERT_TRUE(m);
    std::mt19937 rng(1);
    std::vector<uint32_t> ring, corners, ring2, corners2;
    int checked = 0;
    for (int trial = 0; trial < 40; ++trial) {
      const uint32_t v = rng() % m->vertex_count();
      if (m->is_isolated(v)) continue;
      m->star(v, ring, corners);
      if (ring.size() < 3) continue;
      const uint32_t apex = rng() % ring.size();
      // Skip when a diagonal already exists (the decimation refuses those).
      m->star(ring[apex], ring2, corners2);
      bool clash = false;
      for (uint32_t j = 2; j + 2 <= ring.size(); ++j)
        if (std::find(ring2.begin(), ring2.end(), ring[(apex + j) % ring.size()]) != ring2.end())
          clash = true;
      if (m->is_boundary(v)) {
        m->star(ring.back(), ring2, corners2);
        if (std::find(ring2.begin(), ring2.end(), ring[0]) != ring2.end()) clash = true;
      }
      if (clash || (ring.size() == 3 && !m->is_boundary(v))) continue;
      const uint32_t open = m->is_boundary(v) ? (2 * ring.size() - 1 - apex) % ring.size() : kNone;
      std::vector<uint32_t> rotated(ring.size());
      for (size_t i = 0; i < ring.size(); ++i) rotated[i] = ring[(apex + i) % ring.size()];
      const Vec3i pos = m->positions()[v];
      m->remove_vertex(v, ring, corners, apex);
      expect_manifold(*m);
      // Find the fan at the apex and put a new vertex back.
      m->star(rotated[0], ring2, corners2);
      std::vector<uint8_t> used(corners2.size(), 0);
      std::vector<uint32_t> candidates;
      rank_patch_starts(*m, rotated[0], ring2, used, static_cast<uint32_t>(rotated.size()),
                        candidates);
      ResolvedPatch patch;
      bool found = false;
      for (uint32_t r : candidates) {
        if (resolve_patch(*m, rotated[0], ring2, corners2, r, static_cast<uint32_t>(rotated.size()),
                          patch) &&
            patch.ring == rotated) {
          found = true;
          break;
        }
      }
      ASSERT_TRUE(found) << "the fan of vertex " << v << " is not a candidate at its apex";
      const uint32_t w = m->insert_vertex(patch.ring, patch.fan_corners, open, pos, nullptr);
      expect_manifold(*m);
      m->star(w, ring2, corners2);
      ASSERT_EQ(ring2.size(), ring.size());
      // Same cyclic neighbour order (the new vertex starts anywhere).
      auto it = std::find(ring2.begin(), ring2.end(), ring[0]);
      ASSERT_NE(it, ring2.end());
      std::rotate(ring2.begin(), it, ring2.end());
      EXPECT_EQ(ring2, ring);
      EXPECT_EQ(m->is_boundary(w), m->is_boundary(v));
      ++checked;
    }
    EXPECT_GT(checked, 10);
  }
}

TEST(Quantize, GridIsIsotropicAndRoundTripsWithinHalfAStep) {
  Mesh m = torus(10, 6);
  for (int bits : {8, 12, 20}) {
    auto grid = make_grid(m, bits);
    ASSERT_TRUE(grid);
    const double step = grid->step();
    int32_t max_seen = 0;
    for (const Vec3f& p : m.positions) {
      const Vec3i q = grid->quantize(p);
      const Vec3f back = grid->dequantize(q);
      for (int a = 0; a < 3; ++a) {
        EXPECT_GE(q[a], 0);
        EXPECT_LE(q[a], grid->max_coordinate());
        EXPECT_LE(std::abs(double(back[a]) - p[a]), 0.5 * step + 1e-6);
        max_seen = std::max(max_seen, q[a]);
      }
    }
    EXPECT_EQ(max_seen, grid->max_coordinate());  // the longest axis spans the grid
  }
}

TEST(Encoder, IsDeterministic) {
  Mesh m = combine({icosphere(3, 0.2f), height_field(6, 6)});
  auto a = encode_hcs(m);
  auto b = encode_hcs(m);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(*a, *b);
}

TEST(BaseCoder, OwnCoderRefusesGarbage) {
  std::mt19937 rng(17);
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<uint8_t> junk(rng() % 200);
    for (auto& b : junk) b = static_cast<uint8_t>(rng());
    if (junk.size() >= 8) {
      junk[0] = static_cast<uint8_t>(rng() % 20);
      junk[1] = junk[2] = junk[3] = 0;
      junk[4] = static_cast<uint8_t>(rng() % 30);
      junk[5] = junk[6] = junk[7] = 0;
    }
    const uint32_t nv = junk.size() >= 8 ? junk[0] : 3, nf = junk.size() >= 8 ? junk[4] : 1;
    auto base = decode_base_own(junk, nv, nf, 12);
    if (base) {
      for (const Triangle& t : base->faces)
        for (uint32_t i : t) EXPECT_LT(i, nv);
    }
  }
}

}  // namespace
}  // namespace meshstream
