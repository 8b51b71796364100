// Corners grouped by vertex: corner k at v contributes the outgoing
// half-edge v -> to(k) = vertex(next k) and the incoming third(k) -> v, with
// third(k) = vertex(prev k). The twin of v -> w is the incoming half-edge of
// the corner at v whose third vertex is w, so matching, validation and the
// one-fan check all happen inside one vertex's contiguous bucket.
#include "common/asa/corner_table.h"

#include <algorithm>
#include <string>

#include "common/asa/level_mesh.h"

namespace meshstream::asa {
namespace {

struct Entry {
  uint32_t to, third, corner;
};

std::string edge_name(uint32_t a, uint32_t b) {
  return "edge (" + std::to_string(a) + ", " + std::to_string(b) + ")";
}

}  // namespace

Status build_opposites(const Mesh& mesh, std::vector<uint32_t>& opposite, CornerTableScratch& s) {
  const uint32_t V = mesh.vertex_count(), corners = 3 * mesh.face_count();
  const uint32_t* cv = corners ? mesh.triangles.front().data() : nullptr;
  s.offset.assign(static_cast<size_t>(V) + 1, 0);
  for (uint32_t c = 0; c < corners; ++c) ++s.offset[cv[c] + 1];
  for (uint32_t v = 0; v < V; ++v) s.offset[v + 1] += s.offset[v];
  static_assert(sizeof(Entry) == 12);
  s.entries.resize((static_cast<size_t>(corners) * sizeof(Entry) + 7) / 8);
  Entry* entries = reinterpret_cast<Entry*>(s.entries.data());
  s.corners_at.assign(s.offset.begin(), s.offset.end() - 1);  // fill cursor
  for (uint32_t c = 0; c < corners; ++c) {
    entries[s.corners_at[cv[c]]++] = {cv[next_corner(c)], cv[prev_corner(c)], c};
  }
  opposite.assign(corners, kNone);
  std::vector<uint32_t>& match = s.faces_at;  // per bucket entry: successor around v
  std::vector<uint8_t>& has_pred = s.visited;
  for (uint32_t v = 0; v < V; ++v) {
    Entry* e = entries + s.offset[v];
    const uint32_t n = s.offset[v + 1] - s.offset[v];
    if (n == 0) continue;
    match.assign(n, kNone);
    has_pred.assign(n, 0);
    // The twin of v -> e[i].to is third(j) -> v of the entry j with
    // e[j].third == e[i].to. Large fans are sorted by third first.
    const bool sorted = n > 32;
    if (sorted) std::sort(e, e + n, [](const Entry& a, const Entry& b) { return a.third < b.third; });
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t to = e[i].to;
      uint32_t found = kNone;
      if (sorted) {
        const Entry* lo = std::lower_bound(e, e + n, to, [](const Entry& a, uint32_t x) { return a.third < x; });
        if (lo != e + n && lo->third == to) {
          found = static_cast<uint32_t>(lo - e);
          if (lo + 1 != e + n && (lo + 1)->third == to)
            return make_error(ErrorCode::kNonManifold, edge_name(v, to) + " has more than two faces");
        }
      } else {
        for (uint32_t j = 0; j < n; ++j) {
          if (e[j].third != to) continue;
          if (found != kNone) return make_error(ErrorCode::kNonManifold, edge_name(v, to) + " has more than two faces");
          found = j;
        }
      }
      if (found == kNone) continue;
      if (has_pred[found]) {
        // Two outgoing half-edges v -> to: the same edge twice in one direction.
        return make_error(ErrorCode::kNonManifold,
                          edge_name(v, to) +
                              " is used twice in the same direction (more than two faces, or inconsistent "
                              "orientation) by faces " +
                              std::to_string(e[i].corner / 3) + " and another face");
      }
      has_pred[found] = 1;
      match[i] = found;
      opposite[prev_corner(e[i].corner)] = next_corner(e[found].corner);
    }
    // One fan: at most one entry without predecessor (an open fan's first
    // face); walking successors from it, or from any entry of a closed fan,
    // must visit all n.
    uint32_t start = kNone, starts = 0;
    for (uint32_t i = 0; i < n; ++i)
      if (!has_pred[i]) {
        ++starts;
        start = i;
      }
    if (starts == 0) start = 0;
    uint32_t visited = 0;
    if (starts <= 1) {
      uint32_t i = start;
      do {
        ++visited;
        i = match[i];
      } while (i != kNone && i != start && visited <= n);
    }
    if (starts > 1 || visited != n) {
      // A duplicate outgoing edge leaves two entries without a successor's
      // match; report it as Adjacency does when it is one.
      for (uint32_t i = 0; i < n; ++i)
        for (uint32_t j = i + 1; j < n; ++j)
          if (e[i].to == e[j].to) {
            return make_error(ErrorCode::kNonManifold,
                              edge_name(v, e[i].to) +
                                  " is used twice in the same direction (more than two faces, or inconsistent "
                                  "orientation) by faces " +
                                  std::to_string(e[i].corner / 3) + " and " + std::to_string(e[j].corner / 3));
          }
      return make_error(ErrorCode::kNonManifold,
                        "vertex " + std::to_string(v) + " joins more than one fan of faces (non-manifold vertex)");
    }
  }
  return {};
}

void faces_per_vertex(const CornerTableScratch& s, std::vector<uint32_t>& faces) {
  const size_t V = s.offset.empty() ? 0 : s.offset.size() - 1;
  faces.resize(V);
  for (size_t v = 0; v < V; ++v) faces[v] = s.offset[v + 1] - s.offset[v];
}

}  // namespace meshstream::asa
