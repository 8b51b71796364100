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
  // The uses go straight into their buckets, in face order, each with its
  // larger vertex beside it (a temporary 4 bytes a side), so the buckets are
  // sorted without going back to the faces: at millions of faces that
  // random access was most of the cost.
  EdgeGroups groups;
  groups.uses.resize(offset[n]);
  std::vector<uint32_t> larger(offset[n]);
  {
    std::vector<uint32_t> fill(offset.begin(), offset.end() - 1);
    for (uint32_t f = 0; f < face_count; ++f) {
      const Triangle& t = mesh.triangles[f];
      if (!usable(t)) continue;
      for (uint8_t i = 0; i < 3; ++i) {
        const uint32_t a = t[i], b = t[i == 2 ? 0 : i + 1];
        const uint32_t slot = fill[std::min(a, b)]++;
        groups.uses[slot] = EdgeUse{f, i, a < b};
        larger[slot] = std::max(a, b);
      }
    }
  }
  // Each bucket (the sides whose smaller vertex is v: about 6, 3 edges of 2
  // faces) is sorted by its larger vertex. Stable: the uses of one
  // edge stay in face order (deterministic repair). Insertion sort in place
  // for the usual few; std::stable_sort (through a buffer) for a big fan.
  struct Side {
    uint32_t hi;
    EdgeUse use;
  };
  std::vector<Side> big;
  groups.lo.reserve(groups.uses.size() / 2 + 1);
  groups.hi.reserve(groups.uses.size() / 2 + 1);
  groups.begin.reserve(groups.uses.size() / 2 + 2);
  for (uint32_t v = 0; v < n; ++v) {
    const uint32_t first = offset[v], last = offset[v + 1];
    if (last - first > 32) {
      big.clear();
      for (uint32_t k = first; k < last; ++k) big.push_back({larger[k], groups.uses[k]});
      std::stable_sort(big.begin(), big.end(),
                       [](const Side& a, const Side& b) { return a.hi < b.hi; });
      for (uint32_t k = first; k < last; ++k) {
        larger[k] = big[k - first].hi;
        groups.uses[k] = big[k - first].use;
      }
    } else {
      for (uint32_t k = first + 1; k < last; ++k) {
        const uint32_t hi = larger[k];
        const EdgeUse use = groups.uses[k];
        uint32_t hole = k;
        for (; hole > first && larger[hole - 1] > hi; --hole) {
          larger[hole] = larger[hole - 1];
          groups.uses[hole] = groups.uses[hole - 1];
        }
        larger[hole] = hi;
        groups.uses[hole] = use;
      }
    }
    for (uint32_t k = first; k < last; ++k) {
      if (k == first || larger[k] != larger[k - 1]) {
        groups.lo.push_back(v);
        groups.hi.push_back(larger[k]);
        groups.begin.push_back(k);
      }
    }
  }
  groups.begin.push_back(static_cast<uint32_t>(groups.uses.size()));
  return groups;
}

}  // namespace meshstream
