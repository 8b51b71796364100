// Plane records: see plane_record.h.
#include "common/codec/plane_record.h"

#include <string>

#include "common/codec/byte_io.h"
#include "common/codec/stream_format.h"

namespace meshstream {

namespace {

Status bad(const std::string& what) { return make_error(ErrorCode::kCorrupt, what); }

}  // namespace

Status apply_plane_record(RefinementState& state, std::span<const uint8_t> payload,
                          AppliedRecord& applied) {
  applied.added_vertices.clear();
  applied.touched_faces.clear();
  applied.moved_vertices.clear();
  size_t pos = 1;
  uint32_t first = 0, count = 0;
  if (!state.format.embedded) return bad("plane record in a stream of refinement format 1");
  if (!get_varint(payload, pos, first) || !get_varint(payload, pos, count)) {
    return bad("plane record header is cut short or malformed");
  }
  const uint32_t n = state.mesh.vertex_count();
  if (count == 0 || first >= n || count > n - first) {
    return bad("plane record covers vertices " + std::to_string(first) + " + " +
               std::to_string(count) + " of a mesh of " + std::to_string(n));
  }
  RangeDecoder dec(payload.subspan(pos));
  PlaneBitReader io{dec};
  uint8_t prev_new = 0;
  for (uint32_t v = first; v < first + count; ++v) {
    VertexGeometry& g = state.geometry[v];
    if (g.shift == 0) continue;
    if (!plane_step(state.geometry_models, io, g, prev_new, state.max_coordinate)) {
      return bad("plane record gives vertex " + std::to_string(v) + " a residual beyond the grid");
    }
    state.vertex_shift[v] = g.shift;
    if (g.shift == 0 && g.normal_axis != kBaseVertexAxis) {
      for (int a = 0; a < 3; ++a) {
        const int64_t value =
            int64_t(g.anchor[a]) + ((g.negative >> a) & 1 ? -int64_t(g.mag[a]) : int64_t(g.mag[a]));
        if (value < 0 || value > state.max_coordinate) {
          return bad("plane record puts vertex " + std::to_string(v) +
                     " outside the quantization grid");
        }
      }
    }
    if (dec.exhausted_badly()) return bad("plane record data ends early");
    const Vec3i p = reconstruct(g, state.max_coordinate);
    if (!(p == state.mesh.positions()[v])) {
      state.mesh.set_position(v, p);
      if (applied.record_changes) applied.moved_vertices.push_back(v);
    }
  }
  if (dec.exhausted_badly()) return bad("plane record data ends early");
  return {};
}

std::vector<uint8_t> write_plane_record(RefinementState& state, uint32_t first, uint32_t count,
                                        std::span<const Vec3i> residuals) {
  std::vector<uint8_t> out;
  out.push_back(kRecordPlane);
  put_varint(out, first);
  put_varint(out, count);
  RangeEncoder enc;
  uint8_t prev_new = 0;
  for (uint32_t v = first; v < first + count; ++v) {
    VertexGeometry& g = state.geometry[v];
    if (g.shift == 0) continue;
    PlaneBitWriter io{enc, residuals[v - first]};
    plane_step(state.geometry_models, io, g, prev_new, state.max_coordinate);
    state.vertex_shift[v] = g.shift;
    state.mesh.set_position(v, reconstruct(g, state.max_coordinate));
  }
  const std::vector<uint8_t> coded = enc.finish();
  out.insert(out.end(), coded.begin(), coded.end());
  return out;
}
}  // namespace meshstream
