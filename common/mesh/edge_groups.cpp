#include "common/mesh/edge_groups.h"

#include <algorithm>

namespace meshstream {

EdgeGroups build_edge_groups(const Mesh& mesh) {
  const uint32_t n = mesh.vertex_count();
  const uint32_t face_count = mesh.face_count();
  auto usable = [n](const Triangle& t) {
    return t[0] < n && t[1] < n && t[2] < n && t[0] != t[1] && t[1] != t[2] && t[2] != t[0];
  };

  // Bucket every face side by its smaller vertex (CSR), then sort each small
  // bucket by the larger vertex: linear overall instead of one big sort.
  std::vector<uint32_t> offset(static_cast<size_t>(n) + 1, 0);
  for (const Triangle& t : mesh.triangles) {
    if (!usable(t)) continue;
    for (int i = 0; i < 3; ++i) ++offset[std::min(t[i], t[(i + 1) % 3]) + 1];
  }
  for (uint32_t v = 0; v < n; ++v) offset[v + 1] += offset[v];
  struct Side {
    uint32_t hi;
    EdgeUse use;
  };
  std::vector<Side> sides(offset[n]);
  std::vector<uint32_t> fill(offset.begin(), offset.end() - 1);
  for (uint32_t f = 0; f < face_count; ++f) {
    const Triangle& t = mesh.triangles[f];
    if (!usable(t)) continue;
    for (uint8_t i = 0; i < 3; ++i) {
      const uint32_t a = t[i], b = t[(i + 1) % 3];
      const uint32_t lo = std::min(a, b);
      sides[fill[lo]++] = Side{std::max(a, b), EdgeUse{f, i, a < b}};
    }
  }

  EdgeGroups groups;
  groups.uses.reserve(sides.size());
  groups.lo.reserve(sides.size() / 2 + 1);
  groups.hi.reserve(sides.size() / 2 + 1);
  groups.begin.reserve(sides.size() / 2 + 2);
  for (uint32_t v = 0; v < n; ++v) {
    auto first = sides.begin() + offset[v];
    auto last = sides.begin() + offset[v + 1];
    // Stable so uses of one edge stay in face order (deterministic repair).
    std::stable_sort(first, last, [](const Side& a, const Side& b) { return a.hi < b.hi; });
    for (auto it = first; it != last; ++it) {
      if (it == first || it->hi != (it - 1)->hi) {
        groups.lo.push_back(v);
        groups.hi.push_back(it->hi);
        groups.begin.push_back(static_cast<uint32_t>(groups.uses.size()));
      }
      groups.uses.push_back(it->use);
    }
  }
  groups.begin.push_back(static_cast<uint32_t>(groups.uses.size()));
  return groups;
}

}  // namespace meshstream
