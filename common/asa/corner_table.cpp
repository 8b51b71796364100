#include "common/asa/corner_table.h"

#include <string>

#include "common/asa/level_mesh.h"

namespace meshstream::asa {

Status build_opposites(const Mesh& mesh, std::vector<uint32_t>& opposite, CornerTableScratch& s) {
  const uint32_t V = mesh.vertex_count(), corners = 3 * mesh.face_count();
  const uint32_t* cv = corners ? mesh.triangles.front().data() : nullptr;
  // Bucket every half-edge (the edge faced by corner c, from vertex(next c)
  // to vertex(prev c)) under its smaller vertex. Entry: larger vertex in the
  // high word, corner * 2 + (1 if it runs from larger to smaller) below.
  s.offset.assign(static_cast<size_t>(V) + 1, 0);
  std::vector<uint32_t>& faces_at = s.faces_at;
  faces_at.assign(V, 0);
  for (uint32_t c = 0; c < corners; ++c) {
    const uint32_t a = cv[next_corner(c)], b = cv[prev_corner(c)];
    ++s.offset[(a < b ? a : b) + 1];
    ++faces_at[cv[c]];
  }
  for (uint32_t v = 0; v < V; ++v) s.offset[v + 1] += s.offset[v];
  s.entries.resize(corners);
  s.corners_at.assign(s.offset.begin(), s.offset.end() - 1);  // fill cursor
  for (uint32_t c = 0; c < corners; ++c) {
    const uint32_t a = cv[next_corner(c)], b = cv[prev_corner(c)];
    const uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
    s.entries[s.corners_at[lo]++] = (uint64_t{hi} << 32) | (uint64_t{c} << 1) | (a > b ? 1u : 0u);
  }
  opposite.assign(corners, kNone);
  for (uint32_t v = 0; v < V; ++v) {
    const uint32_t begin = s.offset[v], end = s.offset[v + 1];
    for (uint32_t i = begin; i < end; ++i) {
      const uint64_t ei = s.entries[i];
      const uint32_t hi = static_cast<uint32_t>(ei >> 32);
      const uint32_t ci = static_cast<uint32_t>(ei & 0xFFFFFFFFu) >> 1;
      for (uint32_t j = i + 1; j < end; ++j) {
        const uint64_t ej = s.entries[j];
        if (static_cast<uint32_t>(ej >> 32) != hi) continue;
        const uint32_t cj = static_cast<uint32_t>(ej & 0xFFFFFFFFu) >> 1;
        auto name = [&] { return "edge (" + std::to_string(v) + ", " + std::to_string(hi) + ")"; };
        if ((ei & 1) == (ej & 1)) {
          return make_error(ErrorCode::kNonManifold,
                            name() + " is used twice in the same direction (more than two faces, or "
                                   "inconsistent orientation) by faces " +
                                std::to_string(ci / 3) + " and " + std::to_string(cj / 3));
        }
        if (opposite[ci] != kNone || opposite[cj] != kNone) {
          return make_error(ErrorCode::kNonManifold, name() + " has more than two faces");
        }
        opposite[ci] = cj;
        opposite[cj] = ci;
      }
    }
  }
  // One fan per vertex: walking around from any corner (both ways when the
  // fan is open) must meet every corner of the vertex.
  s.visited.assign(V, 0);
  for (uint32_t c0 = 0; c0 < corners; ++c0) {
    const uint32_t v = cv[c0];
    if (s.visited[v]) continue;
    s.visited[v] = 1;
    uint32_t count = 1;
    uint32_t c = c0;
    bool closed = false;
    for (;;) {  // counter-clockwise
      const uint32_t o = opposite[next_corner(c)];
      if (o == kNone) break;
      c = next_corner(o);
      if (c == c0) {
        closed = true;
        break;
      }
      if (++count > faces_at[v]) break;
    }
    if (!closed) {
      c = c0;
      for (;;) {  // clockwise
        const uint32_t o = opposite[prev_corner(c)];
        if (o == kNone) break;
        c = prev_corner(o);
        if (++count > faces_at[v]) break;
      }
    }
    if (count != faces_at[v]) {
      return make_error(ErrorCode::kNonManifold,
                        "vertex " + std::to_string(v) + " joins more than one fan of faces (non-manifold vertex)");
    }
  }
  return {};
}

}  // namespace meshstream::asa
