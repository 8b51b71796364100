// Flatness test of Cheang's ASA (K. M. Cheang, "Adaptive subdivision
// algorithm in postprocessing of compressed three-dimensional graphic data",
// M.S. thesis, USC, 1998): neighbouring triangles whose normals differ by more
// than the user's t are refined. Crease tagging is our extension.
#include "common/asa/flatness.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace meshstream::asa {

void compute_face_normals(const LevelView& m, std::vector<Vec3f>& normals) {
  normals.resize(m.face_count);
  for (uint32_t f = 0; f < m.face_count; ++f) {
    const Vec3f p0 = m.positions[m.corner_vertex[3 * f]];
    const Vec3f p1 = m.positions[m.corner_vertex[3 * f + 1]];
    const Vec3f p2 = m.positions[m.corner_vertex[3 * f + 2]];
    normals[f] = normalized(cross(p1 - p0, p2 - p0));
  }
}

uint32_t tag_feature_edges(const LevelView& m, float crease_degrees,
                           const std::vector<Vec3f>& normals, std::vector<uint8_t>& feature_edge) {
  const uint32_t corners = 3 * m.face_count;
  feature_edge.resize(corners);
  uint32_t tagged = 0;
  const bool creases = crease_degrees > 0;
  if (!creases) {
    // Boundaries only: a branch-free pass the compiler vectorizes.
    uint8_t* fe = feature_edge.data();
    for (uint32_t c = 0; c < corners; ++c) {
      const uint8_t sharp = m.opposite[c] == kNone;
      fe[c] = sharp;
      tagged += sharp;
    }
    return tagged;
  }
  const float cos_limit = std::cos(crease_degrees * static_cast<float>(std::numbers::pi) / 180.0f);
  for (uint32_t c = 0; c < corners; ++c) {
    const uint32_t o = m.opposite[c];
    uint8_t sharp = o == kNone;
    if (!sharp && creases) {
      // Both corners of the edge compute the same test (dot is symmetric).
      sharp = dot(normals[c / 3], normals[o / 3]) < cos_limit;
    }
    feature_edge[c] = sharp;
    tagged += sharp;
  }
  return tagged;
}

void count_vertex_features(const LevelView& m, std::vector<uint8_t>& vertex_features) {
  vertex_features.assign(m.vertex_count, 0);
  const uint32_t corners = 3 * m.face_count;
  for (uint32_t c = 0; c < corners; ++c) {
    if (!m.feature_edge[c]) continue;
    const uint32_t o = m.opposite[c];
    if (o != kNone && o < c) continue;  // count each edge once
    for (uint32_t v : {m.corner_vertex[next_corner(c)], m.corner_vertex[prev_corner(c)]}) {
      if (vertex_features[v] < 255) ++vertex_features[v];
    }
  }
}

uint32_t count_vertex_faces(const LevelView& m, std::vector<uint32_t>& faces) {
  faces.assign(m.vertex_count, 0);
  const uint32_t corners = 3 * m.face_count;
  for (uint32_t c = 0; c < corners; ++c) ++faces[m.corner_vertex[c]];
  uint32_t largest = 0;
  for (uint32_t n : faces) largest = std::max(largest, n);
  return largest;
}

namespace {

// The camera's veto, kept apart from the flatness rule so either can change
// alone: the edge faced by corner c (between faces c / 3 and o / 3) is worth
// splitting on screen.
bool view_wants(const LevelView& m, const std::vector<Vec3f>& normals, const ViewTest* view,
                uint32_t c, uint32_t o) {
  if (view == nullptr) return true;
  const Vec3f a = m.positions[m.corner_vertex[next_corner(c)]];
  const Vec3f b = m.positions[m.corner_vertex[prev_corner(c)]];
  return view->matters(a, b, normals[c / 3], normals[o / 3]);
}

}  // namespace

uint32_t mark_targets(const LevelView& m, const std::vector<Vec3f>& normals, float t,
                      std::vector<uint8_t>& target, const ViewTest* view) {
  target.resize(m.face_count);
  uint32_t count = 0;
  if (view != nullptr) {
    // With a camera: the (rare) bent edges also ask the view.
    for (uint32_t f = 0; f < m.face_count; ++f) {
      const Vec3f n = normals[f];
      uint8_t bent = 0;
      for (uint32_t c = 3 * f; c < 3 * f + 3 && !bent; ++c) {
        const uint32_t o = m.opposite[c];
        if (o == kNone || m.feature_edge[c]) continue;
        bent = dot(n, normals[o / 3]) <= t && view_wants(m, normals, view, c, o);
      }
      target[f] = bent;
      count += bent;
    }
    return count;
  }
  // Each face tests its own three edges (every edge is tested from both
  // sides: the dot product is symmetric bit for bit), so the loop writes only
  // its own flag and has no data-dependent skip.
  for (uint32_t f = 0; f < m.face_count; ++f) {
    const Vec3f n = normals[f];
    uint8_t bent = 0;
    for (uint32_t c = 3 * f; c < 3 * f + 3; ++c) {
      const uint32_t o = m.opposite[c];
      if (o == kNone || m.feature_edge[c]) continue;  // boundary edges are feature edges too
      bent |= dot(n, normals[o / 3]) <= t;
    }
    target[f] = bent;
    count += bent;
  }
  return count;
}

uint32_t mark_targets_near_fresh(const LevelView& m, const std::vector<Vec3f>& normals,
                                 const std::vector<uint8_t>& fresh, float t,
                                 std::vector<uint8_t>& target, const ViewTest* view) {
  target.assign(m.face_count, 0);
  uint32_t count = 0;
  for (uint32_t f = 0; f < m.face_count; ++f) {
    if (!fresh[f]) continue;
    const Vec3f n = normals[f];
    for (uint32_t c = 3 * f; c < 3 * f + 3; ++c) {
      const uint32_t o = m.opposite[c];
      if (o == kNone || m.feature_edge[c]) continue;
      if (dot(n, normals[o / 3]) <= t && view_wants(m, normals, view, c, o)) {
        const uint32_t g = o / 3;
        count += !target[f] + !target[g];
        target[f] = target[g] = 1;
      }
    }
  }
  return count;
}

}  // namespace meshstream::asa
