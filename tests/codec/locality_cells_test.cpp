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

TEST(LocalityCells, ShiftedOnOddLayers) {
  // 4 cells over a 12-bit grid: 1024 wide; odd layers shift by 512.
  EXPECT_EQ(locality_cell({0, 0, 0}, 0, 4, 12), locality_cell({1023, 1023, 1023}, 0, 4, 12));
  EXPECT_NE(locality_cell({1023, 0, 0}, 0, 4, 12), locality_cell({1024, 0, 0}, 0, 4, 12));
  EXPECT_NE(locality_cell({511, 0, 0}, 1, 4, 12), locality_cell({512, 0, 0}, 1, 4, 12));
  EXPECT_EQ(locality_cell({1023, 0, 0}, 1, 4, 12), locality_cell({1024, 0, 0}, 1, 4, 12));
  EXPECT_EQ(locality_cell({4095, 4095, 4095}, 1, 4, 12), (4u * 5 + 4) * 5 + 4);
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
  options.layer_locks = [](uint32_t layer, const EditableMesh& m, std::vector<uint8_t>& locked) {
    lock_cell_borders(m, layer, 3, 12, locked);
  };
  DecimationResult dec = decimate_layers(std::move(*editable), options);
  ASSERT_GT(dec.layers.size(), 3u);
  size_t removals = 0;
  for (uint32_t layer = 0; layer < dec.layers.size(); ++layer) {
    for (const Removal& r : dec.layers[layer]) {
      const uint32_t cell = locality_cell(q[r.vertex], layer, 3, 12);
      for (uint32_t u : r.ring) ASSERT_EQ(locality_cell(q[u], layer, 3, 12), cell);
      ++removals;
    }
  }
  EXPECT_GT(removals, 2000u);
}

TEST(LocalityCells, StreamDecodesExactly) {
  const Mesh mesh = torus(40, 18);
  EncodeOptions options;
  options.asa_guidance = false;
  options.plane_calibration = 1;
  options.locality_cells = 4;
  auto bytes = encode_hcs(mesh, options);
  ASSERT_TRUE(bytes) << bytes.error().message;
  auto decoded = decode_hcs(*bytes);
  ASSERT_TRUE(decoded) << decoded.error().message;
  auto reference = quantized_reference(mesh, 12);
  ASSERT_TRUE(reference);
  EXPECT_EQ(sorted_positions(*decoded), sorted_positions(*reference));
  EXPECT_EQ(canonical_faces(*decoded), canonical_faces(*reference));
  // Off by default; the same options without cells give another stream.
  options.locality_cells = 0;
  auto plain = encode_hcs(mesh, options);
  ASSERT_TRUE(plain);
  EXPECT_NE(*plain, *bytes);
  options.locality_cells = kMaxLocalityCells + 1;
  auto refused = encode_hcs(mesh, options);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace meshstream
