// The refinement state: see refinement_state.h.
#include "common/codec/refinement_state.h"

#include <utility>

namespace meshstream {

Result<RefinementState> RefinementState::from_base(std::vector<Vec3i> positions,
                                                   std::vector<Triangle> faces, int quant_bits) {
  const uint32_t n = static_cast<uint32_t>(positions.size());
  auto mesh = EditableMesh::build(std::move(positions), std::move(faces));
  if (!mesh) return tl::unexpected(mesh.error());
  RefinementState s;
  s.mesh = std::move(*mesh);
  s.vertices.resize(n);
  s.vertex_layer.assign(n, 0);
  s.vertex_shift.assign(n, 0);
  for (uint32_t v = 0; v < n; ++v) s.vertices[v].next = v + 1 < n ? v + 1 : kNone;
  s.order_head = n > 0 ? 0 : kNone;
  std::vector<uint32_t> ring, corners;
  for (uint32_t v = 0; v < n; ++v) {
    s.mesh.star(v, ring, corners);
    s.vertices[v].valence = static_cast<uint32_t>(ring.size());
  }
  s.max_coordinate = (int32_t(1) << quant_bits) - 1;
  s.geometry.resize(n);
  for (uint32_t v = 0; v < n; ++v) {
    s.geometry[v].anchor = s.mesh.positions()[v];
    s.geometry[v].normal_axis = kBaseVertexAxis;
  }
  return s;
}

Result<RefinementState> RefinementState::from_coarse_base(const std::vector<Vec3i>& coarse,
                                                          std::vector<Triangle> faces,
                                                          int quant_bits, int base_shift) {
  const int32_t max = (int32_t(1) << quant_bits) - 1;
  std::vector<VertexGeometry> geometry(coarse.size());
  std::vector<Vec3i> positions(coarse.size());
  for (size_t v = 0; v < coarse.size(); ++v) {
    VertexGeometry& g = geometry[v];
    for (int a = 0; a < 3; ++a) g.anchor[a] = int32_t(uint32_t(coarse[v][a]) << base_shift);
    g.shift = static_cast<uint8_t>(base_shift);
    g.normal_axis = kBaseVertexAxis;
    positions[v] = reconstruct(g, max);
  }
  auto s = from_base(std::move(positions), std::move(faces), quant_bits);
  if (!s) return s;
  s->geometry = std::move(geometry);
  s->vertex_shift.assign(s->vertices.size(), static_cast<uint8_t>(base_shift));
  return s;
}

}  // namespace meshstream
