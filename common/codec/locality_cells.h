// Spatial cells for the locality experiment of issue 17 (view-dependent
// streaming; docs/view-dependent-records.md): a grid of `per_axis`^3 cells
// over the quantization grid, shifted by half a cell on odd decimation
// layers (so a border locked in one layer is free in the next, as the
// alternating partitions of Nexus's batched multi-triangulation). A vertex
// with a neighbour in another cell is a border vertex and is not removed in
// that layer: every removal's patch then lies inside one cell, so a cell's
// refinements of one layer depend only on coarser refinements of the same
// cell. `EncodeOptions::locality_cells`; off by default.
#pragma once

#include <cstdint>
#include <vector>

#include "common/codec/editable_mesh.h"

namespace meshstream {

inline constexpr uint32_t kMaxLocalityCells = 64;  // per axis

// The cell of grid point q in decimation layer `layer` (0 = the first
// removed, the finest), for a grid of `quant_bits` and `per_axis` >= 1
// cells an axis.
uint32_t locality_cell(Vec3i q, uint32_t layer, uint32_t per_axis, int quant_bits);

// Sets locked[v] = 1 (locked sized to the mesh's vertices) for every vertex
// of a live face whose corners lie in different cells of `layer`. O(faces).
void lock_cell_borders(const EditableMesh& mesh, uint32_t layer, uint32_t per_axis, int quant_bits,
                       std::vector<uint8_t>& locked);

}  // namespace meshstream
