#include "common/mesh/same_faces.h"

#include <algorithm>
#include <array>

namespace meshstream {
namespace {

constexpr uint32_t kNoFace = 0xFFFFFFFFu;

std::array<uint32_t, 3> sorted(const Triangle& t) {
  std::array<uint32_t, 3> k = t;
  if (k[0] > k[1]) std::swap(k[0], k[1]);
  if (k[1] > k[2]) std::swap(k[1], k[2]);
  if (k[0] > k[1]) std::swap(k[0], k[1]);
  return k;
}

}  // namespace

std::vector<uint32_t> first_face_with_same_vertices(const Mesh& mesh) {
  const uint32_t n = mesh.vertex_count();
  const uint32_t face_count = mesh.face_count();
  auto in_range = [n](const Triangle& t) { return t[0] < n && t[1] < n && t[2] < n; };

  std::vector<uint32_t> offset(static_cast<size_t>(n) + 1, 0);
  for (const Triangle& t : mesh.triangles) {
    if (in_range(t)) ++offset[sorted(t)[0] + 1];
  }
  for (uint32_t v = 0; v < n; ++v) offset[v + 1] += offset[v];
  // Each face as its two larger vertices, in its bucket in face order, so
  // the buckets are read without going back to the faces.
  struct Entry {
    uint32_t mid, hi, face;
  };
  std::vector<Entry> bucketed(offset[n]);
  {
    std::vector<uint32_t> fill(offset.begin(), offset.end() - 1);
    for (uint32_t f = 0; f < face_count; ++f) {
      const Triangle& t = mesh.triangles[f];
      if (!in_range(t)) continue;
      const auto k = sorted(t);
      bucketed[fill[k[0]]++] = {k[1], k[2], f};
    }
  }

  std::vector<uint32_t> first(face_count, kNoFace);
  for (uint32_t v = 0; v < n; ++v) {
    Entry* lo = bucketed.data() + offset[v];
    Entry* hi = bucketed.data() + offset[v + 1];
    // By the two larger vertices, ties by face index: the first of a group
    // is its lowest face.
    if (hi - lo > 1) {
      std::sort(lo, hi, [](const Entry& a, const Entry& b) {
        if (a.mid != b.mid) return a.mid < b.mid;
        if (a.hi != b.hi) return a.hi < b.hi;
        return a.face < b.face;
      });
    }
    for (Entry* it = lo; it != hi; ++it) {
      const bool same = it != lo && it->mid == (it - 1)->mid && it->hi == (it - 1)->hi;
      first[it->face] = same ? first[(it - 1)->face] : it->face;
    }
  }
  return first;
}

}  // namespace meshstream
