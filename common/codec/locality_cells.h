// Spatial cells for the locality experiment of issue 17 (view-dependent
// streaming; docs/view-dependent-records.md). Each decimation layer gets a
// grid of n^3 cells over the quantization grid, n a power of two chosen
// from the vertices the layer starts with so a cell holds at least about
// `cell_vertices` of them. The layers with the same n form a *level* and
// share its grid (so a cell's patches of one level build only on that
// cell); n halves as the mesh coarsens by about 4x, as the levels of
// Nexus's batched multi-triangulation coarsen, and each level's grid is
// shifted by a golden-ratio share of its cell (borders of consecutive
// levels do not coincide: a border locked in one level is free in the
// next). Measured against one grid a layer shifted every other layer:
// bench/REPORT.md, "View-dependent records". A vertex of a face
// whose corners lie in different cells is a border vertex and is not
// removed in that layer: every removal's patch then lies inside one cell,
// so a cell's refinements of one layer depend only on coarser refinements
// of the same region. `EncodeOptions::locality_cell_vertices`; off by
// default.
#pragma once

#include <cstdint>
#include <vector>

#include "common/codec/editable_mesh.h"

namespace meshstream {

inline constexpr uint32_t kMaxLocalityCells = 64;  // per axis
inline constexpr uint32_t kMinLocalityCellVertices = 16;
inline constexpr uint32_t kMaxLocalityCellVertices = 1u << 20;

// n for a layer that starts with `alive` vertices: the largest power of two
// at most sqrt(alive / (3 x cell_vertices)) — a surface meets about 3 n^2
// cells of an n^3 grid — and at most kMaxLocalityCells; 1 (one cell,
// nothing locked) below 2. 0 cell_vertices: 1.
uint32_t cells_per_axis(uint32_t alive, uint32_t cell_vertices);

// The cell of grid point q in the grid of `per_axis` >= 2 cells an axis
// (a power of two) over a grid of `quant_bits`, shifted by frac(log2(n) x
// 0.618...) of a cell.
uint32_t locality_cell(Vec3i q, uint32_t per_axis, int quant_bits);

// The grid of each decimation layer, from the vertices each starts with
// (the same sequence on the encoder and on a reader that counts the
// vertices after each restored layer): cells_per_axis, never more than the
// layer before; and half of the layer before's when that layer removed
// under 1/12 of its vertices (its cells' insides are used up: the
// level's borders must go, or the decimation would stall on them); 1 for
// good once a layer starts with fewer than `unlocked_below` vertices (the
// coarse layers, few bytes, then decimate freely: unlocked_for_share).
class CellLevels {
 public:
  explicit CellLevels(uint32_t cell_vertices, uint32_t unlocked_below = 0)
      : cell_vertices_(cell_vertices), unlocked_below_(unlocked_below) {}
  uint32_t next(uint32_t alive);

 private:
  uint32_t cell_vertices_;
  uint32_t unlocked_below_;
  uint32_t previous_alive_ = 0;
  uint32_t per_axis_ = kMaxLocalityCells;
};

// CellLevels' `unlocked_below` for a mesh of `vertices` whose layers lock
// cells only while they start with more than `share` (0..1) of them.
inline uint32_t unlocked_for_share(uint32_t vertices, double share) {
  return static_cast<uint32_t>(share * double(vertices));
}

// Sets locked[v] = 1 (locked sized to the mesh's vertices) for every
// corner of a live face of `mesh` whose corners lie in different cells of
// the grid of `per_axis` cells an axis (nothing below 2). O(faces).
void lock_cell_borders(const EditableMesh& mesh, uint32_t per_axis, int quant_bits,
                       std::vector<uint8_t>& locked);

// Vertices of `mesh` still in a face (removed ones are isolated). O(vertices).
uint32_t live_vertices(const EditableMesh& mesh);

}  // namespace meshstream
