// Uniform level: every edge gets a Butterfly point, every face four children.
// The children's corner table follows from the parent's by index arithmetic
// (face 4f + i = (v_i, m_{i+2}, m_{i+1}), face 4f + 3 = (m_0, m_1, m_2)), which
// is what makes chaining levels cheap.
#include <cstring>

#include "common/asa/edge_points.h"
#include "common/asa/split.h"

namespace meshstream::asa {

namespace {

// Sizes the vertex arrays for V old + E new vertices and copies the old
// ones. With topology, old vertices keep their face count and features.
void start_vertices(const SplitInput& in, uint32_t E, LevelMesh& out) {
  const LevelView& m = in.mesh;
  const uint32_t V = m.vertex_count;
  out.positions.resize(static_cast<size_t>(V) + E);
  std::memcpy(out.positions.data(), m.positions, sizeof(Vec3f) * V);
  start_vertex_attributes(in, V, E, out);
  if (in.want_topology) {
    out.valence.resize(static_cast<size_t>(V) + E);
    out.vertex_features.resize(static_cast<size_t>(V) + E);
    std::memcpy(out.valence.data(), m.valence, sizeof(uint32_t) * V);
    std::memcpy(out.vertex_features.data(), m.vertex_features, V);
  }
}

// Names the edges (the first corner of an edge in corner order names it, the
// other reads the name), with the per-vertex data of the new vertices: a new
// vertex has six faces (three on a boundary) and two feature edges when its
// edge was one; its attributes are its edge's average.
void name_edges(const SplitInput& in, uint32_t* edge_of, LevelMesh& out) {
  const LevelView& m = in.mesh;
  const uint32_t corners = 3 * m.face_count;
  const uint32_t* opp = m.opposite;
  const uint32_t* cv = m.corner_vertex;
  const bool attributes = in.colors != nullptr || in.texcoords != nullptr || in.parents;
  const bool topology = in.want_topology;
  uint32_t next_id = m.vertex_count;
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
    if (attributes) average_vertex_attributes(in, cv[next_corner(c)], cv[prev_corner(c)], id, out);
  }
}

// Face 4f + i = (v_i, m_{i+2}, m_{i+1}), face 4f + 3 = (m_0, m_1, m_2); the
// children's labels and source faces.
void write_children(const SplitInput& in, const uint32_t* edge_of, LevelMesh& out,
                    std::vector<FaceKind>* face_kind) {
  const uint32_t F = in.mesh.face_count;
  const uint32_t* cv = in.mesh.corner_vertex;
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
}

// The children's corner table (opposite, across, feature flags) by index
// arithmetic from the parent's.
void link_children(const LevelView& m, const uint32_t* mid, LevelMesh& out) {
  const uint32_t F = m.face_count;
  const uint32_t* opp = m.opposite;
  const uint32_t* cv = m.corner_vertex;
  out.opposite.resize(12 * static_cast<size_t>(F));
  out.feature_edge.resize(12 * static_cast<size_t>(F));
  out.across.resize(12 * static_cast<size_t>(F));
  uint32_t* oo = out.opposite.data();
  uint32_t* ax = out.across.data();
  uint8_t* fe = out.feature_edge.data();
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

}  // namespace

void split_uniform(const SplitInput& in, SplitScratch& scratch, LevelMesh& out,
                   std::vector<FaceKind>* face_kind) {
  const LevelView& m = in.mesh;
  const uint32_t V = m.vertex_count, corners = 3 * m.face_count;
  const uint32_t* opp = m.opposite;

  // Edge count first, to size the outputs once.
  uint32_t E = 0;
  for (uint32_t c = 0; c < corners; ++c) E += (opp[c] == kNone || c < opp[c]);
  start_vertices(in, E, out);
  std::vector<uint32_t>& edge_of = scratch.edge_vertex;
  edge_of.resize(corners);
  name_edges(in, edge_of.data(), out);

  scratch.points.record_fans = in.want_topology;
  compute_edge_points(m, edge_of.data(), V, E, *in.weights, in.placement, out.positions.data(),
                      scratch.points);
  if (in.want_topology) {
    map_fans_to_uniform_children(scratch.points);
  } else {
    scratch.points.fans_valid = false;
  }

  write_children(in, edge_of.data(), out, face_kind);
  if (in.want_topology) link_children(m, edge_of.data(), out);
}

}  // namespace meshstream::asa
