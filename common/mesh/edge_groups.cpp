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
  // The uses go straight into their buckets, in face order.
  EdgeGroups groups;
  groups.uses.resize(offset[n]);
  {
    std::vector<uint32_t> fill(offset.begin(), offset.end() - 1);
    for (uint32_t f = 0; f < face_count; ++f) {
      const Triangle& t = mesh.triangles[f];
      if (!usable(t)) continue;
      for (uint8_t i = 0; i < 3; ++i) {
        const uint32_t a = t[i], b = t[(i + 1) % 3];
        groups.uses[fill[std::min(a, b)]++] = EdgeUse{f, i, a < b};
      }
    }
  }
  // Each bucket (a vertex's edges, about 3) is sorted by its larger vertex
  // in a small reused buffer that carries that vertex beside each use, so
  // every face is looked at once. Stable: the uses of one edge stay in face
  // order (deterministic repair).
  struct Side {
    uint32_t hi;
    EdgeUse use;
  };
  std::vector<Side> bucket;
  // Insertion sort for the usual few (std::stable_sort allocates a buffer
  // per call); std::stable_sort for the rare big fan.
  auto sort_stably = [](std::vector<Side>& sides) {
    if (sides.size() > 32) {
      std::stable_sort(sides.begin(), sides.end(),
                       [](const Side& a, const Side& b) { return a.hi < b.hi; });
      return;
    }
    for (size_t i = 1; i < sides.size(); ++i) {
      const Side side = sides[i];
      size_t hole = i;
      for (; hole > 0 && sides[hole - 1].hi > side.hi; --hole) sides[hole] = sides[hole - 1];
      sides[hole] = side;
    }
  };
  groups.lo.reserve(groups.uses.size() / 2 + 1);
  groups.hi.reserve(groups.uses.size() / 2 + 1);
  groups.begin.reserve(groups.uses.size() / 2 + 2);
  for (uint32_t v = 0; v < n; ++v) {
    const uint32_t first = offset[v], last = offset[v + 1];
    bucket.clear();
    for (uint32_t k = first; k < last; ++k) {
      const EdgeUse& u = groups.uses[k];
      const Triangle& t = mesh.triangles[u.face];
      bucket.push_back({std::max(t[u.local], t[(u.local + 1) % 3]), u});
    }
    sort_stably(bucket);
    for (uint32_t k = first; k < last; ++k) {
      const Side& side = bucket[k - first];
      groups.uses[k] = side.use;
      if (k == first || side.hi != bucket[k - first - 1].hi) {
        groups.lo.push_back(v);
        groups.hi.push_back(side.hi);
        groups.begin.push_back(k);
      }
    }
  }
  groups.begin.push_back(static_cast<uint32_t>(groups.uses.size()));
  return groups;
}

}  // namespace meshstream
