// The locality experiment's cells (locality_cells.h): with the cell borders
// locked, every removal's patch lies in one cell of its layer, and the
// stream stays an ordinary, exact stream.
#include "common/codec/locality_cells.h"

#include <gtest/gtest.h>

#include "common/codec/decimate.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/codec/quantize.h"
#include "tests/codec/codec_test_util.h"

namespace meshstream {
namespace {

using namespace meshstream::testing;

TEST(LocalityCells, CellsGrowAsTheMeshCoarsens) {
  EXPECT_EQ(cells_per_axis(100000, 512), 8u);  // sqrt(100000 / 1536) = 8.07
  EXPECT_EQ(cells_per_axis(98000, 512), 4u);
  EXPECT_EQ(cells_per_axis(10000, 512), 2u);
  EXPECT_EQ(cells_per_axis(1000, 512), 1u);
  EXPECT_EQ(cells_per_axis(1u << 30, 16), kMaxLocalityCells);
  EXPECT_EQ(cells_per_axis(100000, 0), 1u);
  // Levels: never finer than before; halved after a layer that removed
  // under 1/12 of its vertices.
  CellLevels levels(512);
  EXPECT_EQ(levels.next(100000), 8u);
  EXPECT_EQ(levels.next(80000), 4u);  // by count
  EXPECT_EQ(levels.next(70000), 4u);
  EXPECT_EQ(levels.next(66000), 2u);  // 4000 of 70000 removed: stalled
  EXPECT_EQ(levels.next(60000), 2u);  // 6000 of 66000 removed; never finer again
  // Unlocked below a share of the vertices.
  CellLevels fine_only(512, unlocked_for_share(100000, 0.5));
  EXPECT_EQ(fine_only.next(100000), 8u);
  EXPECT_EQ(fine_only.next(49000), 1u);
  EXPECT_EQ(fine_only.next(48000), 1u);
}

TEST(LocalityCells, GridsOfConsecutiveLevelsAreShifted) {
  // 4 cells over a 12-bit grid: 1024 wide, shifted by frac(2 x 0.618) =
  // 0.236 of a cell (241); 2 cells: 2048 wide, shifted by 0.618 (1265).
  EXPECT_NE(locality_cell({1024 - 241 - 1, 0, 0}, 4, 12), locality_cell({1024 - 241, 0, 0}, 4, 12));
  EXPECT_EQ(locality_cell({1023, 0, 0}, 4, 12), locality_cell({1024, 0, 0}, 4, 12));
  EXPECT_NE(locality_cell({2048 - 1265 - 1, 0, 0}, 2, 12),
            locality_cell({2048 - 1265, 0, 0}, 2, 12));
  EXPECT_EQ(locality_cell({0, 0, 0}, 2, 12), locality_cell({700, 700, 700}, 2, 12));
}

TEST(LocalityCells, EveryPatchLiesInOneCellOfItsLayer) {
  const Mesh mesh = icosphere(4, 0.1f);
  auto grid = make_grid(mesh, 12);
  ASSERT_TRUE(grid);
  const std::vector<Vec3i> q = quantize_positions(mesh, *grid);
  auto editable = EditableMesh::build(q, mesh.triangles);
  ASSERT_TRUE(editable);
  DecimateOptions options;
  options.target_vertices = 100;
  options.threads = 1;
  std::vector<uint32_t> per_axis;  // per layer
  CellLevels levels(32);
  options.layer_locks = [&](uint32_t layer, const EditableMesh& m, std::vector<uint8_t>& locked) {
    per_axis.push_back(levels.next(live_vertices(m)));
    lock_cell_borders(m, per_axis.back(), 12, locked);
    EXPECT_EQ(per_axis.size(), layer + 1);
  };
  DecimationResult dec = decimate_layers(std::move(*editable), options);
  ASSERT_GT(dec.layers.size(), 3u);
  // 2562 vertices, 32 a cell: 4 cells an axis first, fewer as it coarsens.
  ASSERT_GE(per_axis.size(), dec.layers.size());  // a last call may find nothing to remove
  EXPECT_EQ(per_axis.front(), 4u);
  EXPECT_EQ(per_axis.back(), 1u);
  size_t removals = 0, in_cells = 0;
  for (uint32_t layer = 0; layer < dec.layers.size(); ++layer) {
    for (const Removal& r : dec.layers[layer].removals) {
      ++removals;
      if (per_axis[layer] < 2) continue;
      const uint32_t cell = locality_cell(q[r.vertex], per_axis[layer], 12);
      for (uint32_t u : dec.layers[layer].ring(r))
        ASSERT_EQ(locality_cell(q[u], per_axis[layer], 12), cell);
      ++in_cells;
    }
  }
  EXPECT_GT(removals, 2000u);
  EXPECT_GT(in_cells, 1000u);
}

TEST(LocalityCells, StreamDecodesExactly) {
  const Mesh mesh = torus(40, 18);
  EncodeOptions options;
  options.asa_guidance = false;
  options.plane_calibration = 1;
  options.locality_cell_vertices = 16;  // 720 vertices: 4 cells an axis, then 2
  auto bytes = encode_hcs(mesh, options);
  ASSERT_TRUE(bytes) << bytes.error().message;
  auto decoded = decode_hcs(*bytes);
  ASSERT_TRUE(decoded) << decoded.error().message;
  auto reference = quantized_reference(mesh, 12);
  ASSERT_TRUE(reference);
  EXPECT_EQ(sorted_positions(*decoded), sorted_positions(*reference));
  EXPECT_EQ(canonical_faces(*decoded), canonical_faces(*reference));
  // Off by default; the same options without cells give another stream.
  options.locality_cell_vertices = 0;
  auto plain = encode_hcs(mesh, options);
  ASSERT_TRUE(plain);
  EXPECT_NE(*plain, *bytes);
  options.locality_cell_vertices = kMinLocalityCellVertices - 1;
  auto refused = encode_hcs(mesh, options);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::kInvalidArgument);
  options.locality_cell_vertices = kMaxLocalityCellVertices + 1;
  refused = encode_hcs(mesh, options);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::kInvalidArgument);
  options.locality_cell_vertices = 16;
  options.locality_unlocked_share = 1.5;
  refused = encode_hcs(mesh, options);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace meshstream
