// Cells with locked borders: see locality_cells.h.
#include "common/codec/locality_cells.h"

#include <algorithm>
#include <cmath>

namespace meshstream {

uint32_t cells_per_axis(uint32_t alive, uint32_t cell_vertices) {
  if (cell_vertices == 0) return 1;
  const double limit = std::sqrt(double(alive) / (3.0 * double(cell_vertices)));
  uint32_t n = 1;
  while (n < kMaxLocalityCells && double(2 * n) <= limit) n *= 2;
  return n;
}

uint32_t locality_cell(Vec3i q, uint32_t per_axis, int quant_bits) {
  const int64_t extent = int64_t(1) << quant_bits;
  const int64_t size = (extent + per_axis - 1) / per_axis;
  const double turn = std::log2(double(per_axis)) * 0.6180339887498949;
  const int64_t offset = static_cast<int64_t>((turn - std::floor(turn)) * double(size));
  const uint32_t span = per_axis + 1;  // the shifted grid reaches one cell further
  uint32_t id = 0;
  for (int a = 0; a < 3; ++a)
    id = id * span + static_cast<uint32_t>((int64_t(q[a]) + offset) / size);
  return id;
}

uint32_t CellLevels::next(uint32_t alive) {
  if (alive < unlocked_below_) per_axis_ = 1;
  uint32_t n = std::min(per_axis_, cells_per_axis(alive, cell_vertices_));
  if (previous_alive_ > 0 && n > 1 && n == per_axis_ &&
      uint64_t(previous_alive_ - std::min(alive, previous_alive_)) * 12 < previous_alive_)
    n /= 2;
  previous_alive_ = alive;
  per_axis_ = n;
  return n;
}

uint32_t live_vertices(const EditableMesh& mesh) {
  uint32_t alive = 0;
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) alive += !mesh.is_isolated(v);
  return alive;
}

void lock_cell_borders(const EditableMesh& mesh, uint32_t per_axis, int quant_bits,
                       std::vector<uint8_t>& locked) {
  locked.assign(mesh.vertex_count(), 0);
  if (per_axis < 2) return;
  const auto& positions = mesh.positions();
  for (uint32_t f = 0; f < mesh.face_slot_count(); ++f) {
    if (mesh.face_dead(f)) continue;
    const Triangle& t = mesh.faces()[f];
    const uint32_t c0 = locality_cell(positions[t[0]], per_axis, quant_bits);
    const uint32_t c1 = locality_cell(positions[t[1]], per_axis, quant_bits);
    const uint32_t c2 = locality_cell(positions[t[2]], per_axis, quant_bits);
    if (c0 != c1 || c1 != c2) locked[t[0]] = locked[t[1]] = locked[t[2]] = 1;
  }
}

}  // namespace meshstream
