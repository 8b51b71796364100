// The mesh one subdivision level works on: a corner table plus the flags the
// Butterfly stencils and the closure need. Internal to common/asa.
//
// Corner c = 3 * face + i sits at vertex corner_vertex[c] and faces the edge
// from vertex(next(c)) to vertex(prev(c)); opposite[c] is the corner across
// that edge (kNone on a boundary). A "feature" edge is a boundary edge or a
// crease edge; the Butterfly stencils never reach across one.
#pragma once

#include <cstdint>
#include <vector>

#include "common/mesh/adjacency.h"
#include "common/mesh/mesh.h"

namespace meshstream::asa {

inline uint32_t next_corner(uint32_t c) { return c % 3 == 2 ? c - 2 : c + 1; }
inline uint32_t prev_corner(uint32_t c) { return c % 3 == 0 ? c + 2 : c - 1; }

// across[c] = vertex of opposite[c] (kNone where there is none), for
// `corners` corners. O(corners).
inline void fill_across(const uint32_t* corner_vertex, const uint32_t* opposite, uint32_t corners,
                        std::vector<uint32_t>& across) {
  across.resize(corners);
  for (uint32_t c = 0; c < corners; ++c) {
    const uint32_t o = opposite[c];
    across[c] = o == kNone ? kNone : corner_vertex[o];
  }
}

// Green (bisected) faces come in consecutive pairs made from a parent
// (A, B, C) split at M on BC: first = (A, B, M), second = (A, M, C). The apex
// A is local corner 0 of both; the shared edge A-M is internal to the pair.
enum GreenKind : uint8_t { kNotGreen = 0, kGreenFirst = 1, kGreenSecond = 2 };

// Read-only view of one level; level 0 points into the caller's Mesh.
struct LevelView {
  const Vec3f* positions = nullptr;
  const uint32_t* corner_vertex = nullptr;  // 3 per face
  const uint32_t* opposite = nullptr;       // 3 per face
  const uint32_t* across =
      nullptr;  // per corner: vertex of the opposite corner (kNone on a boundary)
  const uint8_t* feature_edge = nullptr;     // per corner: the faced edge is boundary or crease
  const uint8_t* vertex_features = nullptr;  // per vertex: feature edges at it (saturating)
  const uint32_t* valence = nullptr;         // per vertex: faces around it (= valence if interior)
  const uint8_t* green = nullptr;            // per face GreenKind, may be null (no greens)
  uint32_t vertex_count = 0;
  uint32_t face_count = 0;
};

// Topology and positions of an intermediate level (owned, reused).
struct LevelMesh {
  std::vector<Vec3f> positions;
  std::vector<Triangle> triangles;
  std::vector<uint32_t> opposite;
  std::vector<uint32_t> across;
  std::vector<uint8_t> feature_edge;
  std::vector<uint8_t> vertex_features;
  std::vector<uint32_t> valence;
  std::vector<uint8_t> green;
  std::vector<Vec4f> colors;
  std::vector<Vec2f> texcoords;
  std::vector<uint32_t> source;  // per face: the input face it descends from (when tracked)
  std::vector<Vec3f> normals;    // per face: unit normal (adaptive levels after the first)
  std::vector<uint8_t> fresh;    // per face: new at this level (not a copy of a parent face)

  LevelView view() const {
    LevelView v;
    v.positions = positions.data();
    v.corner_vertex = triangles.empty() ? nullptr : triangles.front().data();
    v.opposite = opposite.data();
    v.across = across.empty() ? nullptr : across.data();
    v.feature_edge = feature_edge.data();
    v.vertex_features = vertex_features.data();
    v.valence = valence.data();
    v.green = green.empty() ? nullptr : green.data();
    v.vertex_count = static_cast<uint32_t>(positions.size());
    v.face_count = static_cast<uint32_t>(triangles.size());
    return v;
  }
};

static_assert(sizeof(Triangle) == 3 * sizeof(uint32_t), "Triangle must be three packed indices");

}  // namespace meshstream::asa
