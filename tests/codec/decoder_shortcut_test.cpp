// The decoder's fast paths compute exactly what the encoder's shared steps
// compute (the stream would desynchronise otherwise): select_patch_start
// against the full ranking, with ties, boundaries and taken faces.
#include <gtest/gtest.h>

#include <random>

#include "common/codec/editable_mesh.h"
#include "common/codec/quantize.h"
#include "common/codec/refinement_codec.h"
#include "tests/codec/codec_test_util.h"

namespace meshstream {
namespace {

using namespace meshstream::testing;

TEST(DecoderShortcut, SelectPatchStartIsTheRankedStart) {
  // A coarse grid makes many equal diagonal lengths (ties by r); the height
  // field has boundary stars.
  for (const Mesh& input : {icosphere(2, 0.1f), height_field(8, 7), torus(10, 6)}) {
    for (int bits : {kMinQuantBits, 12}) {
      auto grid = make_grid(input, bits);
      ASSERT_TRUE(grid);
      auto m = EditableMesh::build(quantize_positions(input, *grid), input.triangles);
      ASSERT_TRUE(m);
      std::mt19937 rng(7);
      std::vector<uint32_t> ring, corners, ranked, scratch;
      int compared = 0;
      for (uint32_t v = 0; v < m->vertex_count(); ++v) {
        m->star(v, ring, corners);
        std::vector<uint8_t> used(corners.size(), 0);
        for (int pattern = 0; pattern < 3; ++pattern) {
          for (auto& u : used) u = pattern == 0 ? 0 : (rng() % 4 == 0 ? 1 : 0);
          for (uint32_t k = 3; k <= corners.size() + 2; ++k) {
            rank_patch_starts(*m, v, ring, used, k, ranked);
            for (uint32_t rank = 0; rank <= ranked.size() + 1; ++rank) {
              const uint32_t r = select_patch_start(*m, v, ring, used, k, rank, scratch);
              if (rank < ranked.size()) {
                ASSERT_EQ(r, ranked[rank]) << "vertex " << v << " k " << k << " rank " << rank;
                ++compared;
              } else {
                ASSERT_EQ(r, kNone);
              }
            }
          }
        }
      }
      EXPECT_GT(compared, 100);
    }
  }
}

}  // namespace
}  // namespace meshstream
