// Cells with locked borders: see locality_cells.h.
#include "common/codec/locality_cells.h"

namespace meshstream {

uint32_t locality_cell(Vec3i q, uint32_t layer, uint32_t per_axis, int quant_bits) {
  const int64_t extent = int64_t(1) << quant_bits;
  const int64_t size = (extent + per_axis - 1) / per_axis;
  const int64_t offset = (layer & 1) ? size / 2 : 0;
  const uint32_t span = per_axis + 1;  // the shifted grid reaches one cell further
  uint32_t id = 0;
  for (int a = 0; a < 3; ++a)
    id = id * span + static_cast<uint32_t>((int64_t(q[a]) + offset) / size);
  return id;
}

void lock_cell_borders(const EditableMesh& mesh, uint32_t layer, uint32_t per_axis, int quant_bits,
                       std::vector<uint8_t>& locked) {
  locked.assign(mesh.vertex_count(), 0);
  const auto& positions = mesh.positions();
  for (uint32_t f = 0; f < mesh.face_slot_count(); ++f) {
    if (mesh.face_dead(f)) continue;
    const Triangle& t = mesh.faces()[f];
    const uint32_t c0 = locality_cell(positions[t[0]], layer, per_axis, quant_bits);
    const uint32_t c1 = locality_cell(positions[t[1]], layer, per_axis, quant_bits);
    const uint32_t c2 = locality_cell(positions[t[2]], layer, per_axis, quant_bits);
    if (c0 != c1 || c1 != c2) locked[t[0]] = locked[t[1]] = locked[t[2]] = 1;
  }
}

}  // namespace meshstream
