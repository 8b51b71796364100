// Uniform level: every edge gets a Butterfly point, every face four children.
// The children's corner table follows from the parent's by index arithmetic
// (face 4f + i = (v_i, m_{i+2}, m_{i+1}), face 4f + 3 = (m_0, m_1, m_2)), which
// is what makes chaining levels cheap.
#include <cstring>

#include "common/asa/edge_points.h"
#include "common/asa/split.h"

namespace meshstream::asa {

void split_uniform(const SplitInput& in, SplitScratch& scratch, LevelMesh& out,
                   std::vector<FaceKind>* face_kind) {
  const LevelView& m = in.mesh;
  const uint32_t V = m.vertex_count, F = m.face_count, corners = 3 * F;
  const uint32_t* opp = m.opposite;
  const uint32_t* cv = m.corner_vertex;

  // One pass over the corners: the first corner of an edge (in corner
  // order) names it and computes its point; the other reads the name.
  std::vector<uint32_t>& edge_of = scratch.edge_vertex;
  edge_of.resize(corners);
  // Edge count first, to size the outputs once.
  uint32_t E = 0;
  for (uint32_t c = 0; c < corners; ++c) E += (opp[c] == kNone || c < opp[c]);
  const bool colors = in.colors != nullptr, texcoords = in.texcoords != nullptr;
  const bool topology = in.want_topology;
  out.positions.resize(static_cast<size_t>(V) + E);
  Vec3f* pos = out.positions.data();
  std::memcpy(pos, m.positions, sizeof(Vec3f) * V);
  if (colors) {
    out.colors.resize(static_cast<size_t>(V) + E);
    std::memcpy(out.colors.data(), in.colors, sizeof(Vec4f) * V);
  } else {
    out.colors.clear();
  }
  if (texcoords) {
    out.texcoords.resize(static_cast<size_t>(V) + E);
    std::memcpy(out.texcoords.data(), in.texcoords, sizeof(Vec2f) * V);
  } else {
    out.texcoords.clear();
  }
  if (topology) {
    // Old vertices keep their face count and features; a new vertex has six
    // faces (three on a boundary) and two feature edges when its edge was one.
    out.valence.resize(static_cast<size_t>(V) + E);
    out.vertex_features.resize(static_cast<size_t>(V) + E);
    std::memcpy(out.valence.data(), m.valence, sizeof(uint32_t) * V);
    std::memcpy(out.vertex_features.data(), m.vertex_features, V);
  }

  // Name the edges (the first corner of an edge in corner order names it),
  // with the per-vertex data of the new vertices.
  uint32_t next_id = V;
  const uint8_t* parent_feature = m.feature_edge;
  for (uint32_t c = 0; c < corners; ++c) {
    const uint32_t o = opp[c];
    if (o != kNone && o < c) {
      edge_of[c] = edge_of[o];
      continue;
    }
    const uint32_t id = next_id++;
    edge_of[c] = id;
    if (topology) {
      out.valence[id] = o == kNone ? 3 : 6;
      out.vertex_features[id] = parent_feature[c] ? 2 : 0;
    }
    if (colors | texcoords) {
      const uint32_t a = cv[next_corner(c)], b = cv[prev_corner(c)];
      if (colors) {
        const Vec4f ca = in.colors[a], cb = in.colors[b];
        out.colors[id] = {(ca.x + cb.x) * 0.5f, (ca.y + cb.y) * 0.5f, (ca.z + cb.z) * 0.5f,
                          (ca.w + cb.w) * 0.5f};
      }
      if (texcoords) {
        const Vec2f ta = in.texcoords[a], tb = in.texcoords[b];
        out.texcoords[id] = {(ta.x + tb.x) * 0.5f, (ta.y + tb.y) * 0.5f};
      }
    }
  }
  scratch.points.record_fans = in.want_topology;
  compute_edge_points(m, edge_of.data(), V, E, *in.weights, in.placement, pos, scratch.points);
  if (in.want_topology) {
    map_fans_to_uniform_children(scratch.points);
  } else {
    scratch.points.fans_valid = false;
  }

  out.triangles.resize(4 * static_cast<size_t>(F));
  uint32_t* t = out.triangles.front().data();
  for (uint32_t f = 0; f < F; ++f) {
    const uint32_t v0 = cv[3 * f], v1 = cv[3 * f + 1], v2 = cv[3 * f + 2];
    const uint32_t m0 = edge_of[3 * f], m1 = edge_of[3 * f + 1], m2 = edge_of[3 * f + 2];
    uint32_t* q = t + 12 * static_cast<size_t>(f);
    q[0] = v0;
    q[1] = m2;
    q[2] = m1;
    q[3] = v1;
    q[4] = m0;
    q[5] = m2;
    q[6] = v2;
    q[7] = m1;
    q[8] = m0;
    q[9] = m0;
    q[10] = m1;
    q[11] = m2;
  }
  if (face_kind) face_kind->assign(4 * static_cast<size_t>(F), FaceKind::kTarget);
  if (in.source) {
    out.source.resize(4 * static_cast<size_t>(F));
    for (uint32_t f = 0; f < F; ++f)
      for (uint32_t i = 0; i < 4; ++i) out.source[4 * f + i] = in.source[f];
  } else {
    out.source.clear();
  }

  if (!in.want_topology) return;
  out.opposite.resize(12 * static_cast<size_t>(F));
  out.feature_edge.resize(12 * static_cast<size_t>(F));
  out.across.resize(12 * static_cast<size_t>(F));
  uint32_t* oo = out.opposite.data();
  uint32_t* ax = out.across.data();
  uint8_t* fe = out.feature_edge.data();
  const uint32_t* mid = edge_of.data();
  for (uint32_t f = 0; f < F; ++f) {
    const uint32_t base = 12 * f;  // first corner of child 4f
    for (uint32_t i = 0; i < 3; ++i) {
      oo[base + 3 * i] = base + 9 + i;  // corner child's inner edge <-> middle child
      oo[base + 9 + i] = base + 3 * i;
      ax[base + 3 * i] = mid[3 * f + i];
      ax[base + 9 + i] = cv[3 * f + i];
      fe[base + 3 * i] = 0;
      fe[base + 9 + i] = 0;
    }
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t c = 3 * f + k;
      // Halves of the parent edge faced by corner k: near v_{k+1} it is faced
      // by corner 2 of child k+1, near v_{k+2} by corner 1 of child k+2.
      const uint32_t near_next = base + 3 * ((k + 1) % 3) + 2;
      const uint32_t near_prev = base + 3 * ((k + 2) % 3) + 1;
      const uint32_t o = opp[c];
      if (o == kNone) {
        oo[near_next] = oo[near_prev] = kNone;
        ax[near_next] = ax[near_prev] = kNone;
      } else {
        // Across each half lies a midpoint of the neighbour g: corner 1 of
        // its child j+2 is m_{j+1}, corner 2 of its child j+1 is m_{j+2}.
        const uint32_t g = o / 3, j = o % 3;
        oo[near_next] = 12 * g + 3 * ((j + 2) % 3) + 1;
        oo[near_prev] = 12 * g + 3 * ((j + 1) % 3) + 2;
        ax[near_next] = mid[3 * g + (j + 1) % 3];
        ax[near_prev] = mid[3 * g + (j + 2) % 3];
      }
      fe[near_next] = fe[near_prev] = m.feature_edge[c];
    }
  }
  out.green.clear();
}

}  // namespace meshstream::asa
