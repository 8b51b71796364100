#include "common/mesh/adjacency.h"

#include <string>

namespace meshstream {
namespace {

std::string edge_name(uint32_t a, uint32_t b) {
  return "edge (" + std::to_string(a) + ", " + std::to_string(b) + ")";
}

}  // namespace

// Each face's three vertex indices, checked: in range, no repeats.
Status Adjacency::copy_corners(const Mesh& mesh) {
  const uint32_t vertex_count = mesh.vertex_count();
  corner_vertex_.resize(mesh.face_count() * 3);
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    const Triangle& t = mesh.triangles[f];
    for (uint32_t i = 0; i < 3; ++i) {
      if (t[i] >= vertex_count) {
        return make_error(
            ErrorCode::kInvalidMesh,
            "triangle " + std::to_string(f) + " refers to missing vertex " + std::to_string(t[i]));
      }
      corner_vertex_[3 * f + i] = t[i];
    }
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) {
      return make_error(ErrorCode::kInvalidMesh,
                        "triangle " + std::to_string(f) + " repeats a vertex (degenerate)");
    }
  }
  return {};
}

// Opposite corners through the outgoing half-edges grouped by start vertex
// (CSR); an edge used twice in one direction or by more than two faces is
// refused. Corner c stands for the half-edge vertex(next(c)) ->
// vertex(prev(c)), the edge it faces.
Status Adjacency::link_opposites(uint32_t vertex_count) {
  const uint32_t corner_count = this->corner_count();
  std::vector<uint32_t> offset(vertex_count + 1, 0);
  for (uint32_t c = 0; c < corner_count; ++c) ++offset[corner_vertex_[next(c)] + 1];
  for (uint32_t v = 0; v < vertex_count; ++v) offset[v + 1] += offset[v];
  std::vector<uint32_t> fill(offset.begin(), offset.end() - 1);
  std::vector<uint32_t> outgoing(corner_count);
  for (uint32_t c = 0; c < corner_count; ++c) outgoing[fill[corner_vertex_[next(c)]]++] = c;

  opposite_.assign(corner_count, kNone);
  for (uint32_t c = 0; c < corner_count; ++c) {
    const uint32_t from = corner_vertex_[next(c)];
    const uint32_t to = corner_vertex_[prev(c)];
    // Same direction twice: an edge with >2 faces or flipped orientation.
    uint32_t match = kNone;
    for (uint32_t k = offset[from]; k < offset[from + 1]; ++k) {
      uint32_t other = outgoing[k];
      if (other != c && corner_vertex_[prev(other)] == to) {
        return make_error(ErrorCode::kNonManifold,
                          edge_name(from, to) +
                              " is used twice in the same direction (more than two faces, or "
                              "inconsistent orientation) by faces " +
                              std::to_string(face(c)) + " and " + std::to_string(face(other)));
      }
    }
    for (uint32_t k = offset[to]; k < offset[to + 1]; ++k) {
      uint32_t other = outgoing[k];
      if (corner_vertex_[prev(other)] == from) {
        if (match != kNone) {
          return make_error(ErrorCode::kNonManifold,
                            edge_name(from, to) + " has more than two faces");
        }
        match = other;
      }
    }
    opposite_[c] = match;
  }
  return {};
}

// Vertex corners: start each boundary vertex at the face that cannot swing
// clockwise, then check that one fan covers every corner of the vertex.
Status Adjacency::find_vertex_fans(uint32_t vertex_count) {
  const uint32_t corner_count = this->corner_count();
  vertex_corner_.assign(vertex_count, kNone);
  is_boundary_.assign(vertex_count, 0);
  std::vector<uint32_t> corners_at(vertex_count, 0);
  for (uint32_t c = 0; c < corner_count; ++c) {
    const uint32_t v = corner_vertex_[c];
    ++corners_at[v];
    if (opposite_[prev(c)] == kNone) {
      if (is_boundary_[v]) {
        return make_error(ErrorCode::kNonManifold,
                          "vertex " + std::to_string(v) +
                              " joins more than one fan of faces (non-manifold vertex)");
      }
      is_boundary_[v] = 1;
      vertex_corner_[v] = c;
    } else if (vertex_corner_[v] == kNone) {
      vertex_corner_[v] = c;
    }
  }
  for (uint32_t v = 0; v < vertex_count; ++v) {
    const uint32_t start = vertex_corner_[v];
    if (start == kNone) continue;
    uint32_t visited = 0;
    uint32_t c = start;
    do {
      ++visited;
      c = swing_ccw(c);
    } while (c != kNone && c != start && visited <= corners_at[v]);
    if (visited != corners_at[v]) {
      return make_error(ErrorCode::kNonManifold,
                        "vertex " + std::to_string(v) +
                            " joins more than one fan of faces (non-manifold vertex)");
    }
  }
  return {};
}

void Adjacency::count_edges() {
  for (uint32_t c = 0; c < corner_count(); ++c) {
    if (opposite_[c] == kNone) {
      ++boundary_edge_count_;
      ++edge_count_;
    } else if (c < opposite_[c]) {
      ++edge_count_;
    }
  }
}

Result<Adjacency> Adjacency::build(const Mesh& mesh) {
  Adjacency adj;
  if (auto ok = adj.copy_corners(mesh); !ok) return tl::unexpected(ok.error());
  if (auto ok = adj.link_opposites(mesh.vertex_count()); !ok) return tl::unexpected(ok.error());
  if (auto ok = adj.find_vertex_fans(mesh.vertex_count()); !ok) return tl::unexpected(ok.error());
  adj.count_edges();
  return adj;
}

uint32_t Adjacency::valence(uint32_t v) const {
  const uint32_t start = vertex_corner_[v];
  if (start == kNone) return 0;
  uint32_t faces = 0;
  uint32_t c = start;
  do {
    ++faces;
    c = swing_ccw(c);
  } while (c != kNone && c != start);
  return is_boundary_[v] ? faces + 1 : faces;
}

void Adjacency::vertex_corners(uint32_t v, std::vector<uint32_t>& out) const {
  out.clear();
  const uint32_t start = vertex_corner_[v];
  if (start == kNone) return;
  uint32_t c = start;
  do {
    out.push_back(c);
    c = swing_ccw(c);
  } while (c != kNone && c != start);
}

void Adjacency::one_ring(uint32_t v, std::vector<uint32_t>& out) const {
  out.clear();
  const uint32_t start = vertex_corner_[v];
  if (start == kNone) return;
  uint32_t c = start;
  uint32_t last = start;
  do {
    out.push_back(corner_vertex_[next(c)]);
    last = c;
    c = swing_ccw(c);
  } while (c != kNone && c != start);
  if (is_boundary_[v]) out.push_back(corner_vertex_[prev(last)]);
}

}  // namespace meshstream
