// Plane-record grouping: see plane_groups.h.
#include "common/codec/plane_groups.h"

#include <algorithm>
#include <cstdlib>

#include "common/codec/range_coder.h"

namespace meshstream {
namespace {

// A plane step's true bits without coding them (for estimates).
struct PlaneBitOracle {
  Vec3i residual;
  uint32_t bit(BitModel&, int axis, int below) {
    return (uint32_t(std::abs(residual[axis])) >> below) & 1u;
  }
  uint32_t sign(BitModel&, int axis) { return residual[axis] < 0 ? 1u : 0u; }
};

// PlaneBitWriter's bits through the plain models instead of the context ones.
struct PlainPlaneWriter {
  PlaneBitWriter writer;
  PlainPlaneModels& m;
  uint32_t bit(BitModel&, int axis, int below) { return writer.bit(m.bit[below], axis, below); }
  uint32_t sign(BitModel&, int axis) { return writer.sign(m.sign, axis); }
};

}  // namespace

size_t plain_plane_bytes(const RefinementState& s, const EncoderTruth& t, uint32_t first,
                         uint32_t count, PlainPlaneModels& models) {
  RangeEncoder enc;
  GeometryModels unused;
  uint8_t prev_new = 0;
  for (uint32_t v = first; v < first + count; ++v) {
    VertexGeometry geo = s.geometry[v];
    if (geo.shift == 0) continue;
    PlainPlaneWriter io{{enc, t.position(v) - geo.anchor}, models};
    plane_step(unused, io, geo, prev_new, s.max_coordinate);
  }
  return enc.finish().size();
}

void evaluate_group(const RefinementState& s, EncoderTruth& t, PlaneGroup& g) {
  g.pending = 0;
  g.top_plane = 0;
  g.scaled_drop = 0;
  GeometryModels scratch;  // the oracle ignores models
  for (uint32_t v = g.first; v < g.first + g.count; ++v) {
    VertexGeometry geo = s.geometry[v];
    if (geo.shift == 0) continue;
    ++g.pending;
    g.top_plane = std::max(g.top_plane, geo.shift - 1);
    const Vec3i before = s.mesh.positions()[v];
    PlaneBitOracle io{t.position(v) - geo.anchor};
    uint8_t prev_new = 0;
    plane_step(scratch, io, geo, prev_new, s.max_coordinate);
    const Vec3i after = reconstruct(geo, s.max_coordinate);
    g.scaled_drop += t.weight[v] * (vertex_error2(t, v, before) - vertex_error2(t, v, after)) / 6.0;
  }
}

}  // namespace meshstream
