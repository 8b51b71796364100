// EditableMesh: see editable_mesh.h for the slot and ring conventions.
#include "common/codec/editable_mesh.h"

#include <algorithm>

namespace meshstream {

Result<EditableMesh> EditableMesh::build(std::vector<Vec3i> positions,
                                         std::vector<Triangle> faces) {
  Mesh plain;
  plain.positions.resize(positions.size());
  plain.triangles = faces;
  auto adj = Adjacency::build(plain);
  if (!adj) return tl::unexpected(adj.error());
  EditableMesh m;
  m.positions_ = std::move(positions);
  m.faces_ = std::move(faces);
  m.opposite_.resize(adj->corner_count());
  for (uint32_t c = 0; c < adj->corner_count(); ++c) m.opposite_[c] = adj->opposite(c);
  m.vertex_corner_.resize(adj->vertex_count());
  m.boundary_.resize(adj->vertex_count());
  for (uint32_t v = 0; v < adj->vertex_count(); ++v) {
    m.vertex_corner_[v] = adj->vertex_corner(v);
    m.boundary_[v] = adj->is_boundary_vertex(v) ? 1 : 0;
  }
  return m;
}

void EditableMesh::star(uint32_t v, std::vector<uint32_t>& ring,
                        std::vector<uint32_t>& corners) const {
  ring.clear();
  corners.clear();
  const uint32_t start = vertex_corner_[v];
  if (start == kNone) return;
  const uint32_t* corner_vertex = reinterpret_cast<const uint32_t*>(faces_.data());
  const uint32_t* opposite = opposite_.data();
  uint32_t c = start;
  uint32_t last = start;
  // The bound only guards against a broken table; a valid one ends the loop.
  for (size_t guard = opposite_.size(); guard > 0; --guard) {
    corners.push_back(c);
    const uint32_t n = next(c);
    ring.push_back(corner_vertex[n]);
    last = c;
    const uint32_t o = opposite[n];
    if (o == kNone) break;
    c = next(o);
    if (c == start) break;
  }
  if (boundary_[v]) ring.push_back(corner_vertex[prev(last)]);
}

void EditableMesh::remove_vertex(uint32_t v, const std::vector<uint32_t>& ring,
                                 const std::vector<uint32_t>& corners, uint32_t a) {
  const uint32_t k = static_cast<uint32_t>(ring.size());
  auto R = [&](uint32_t i) { return ring[(a + i) % k]; };
  // Relative to the apex: o[i] is the corner outside ring edge e_i =
  // (R_a+i, R_a+i+1), slot[i] the face of star face S_a+i; for a boundary
  // vertex the star misses the face of its open edge (ring[k-1], ring[0]).
  const uint32_t open = boundary_[v] ? (k - 1 + k - a) % k : kNone;
  uint32_t o[kMaxPatchValence], slot[kMaxPatchValence];
  for (uint32_t i = 0; i < k; ++i) {
    if (i == open) {
      o[i] = kNone;
      slot[i] = kNone;
    } else {
      const uint32_t c = corners[(a + i) % k];
      o[i] = opposite_[c];
      slot[i] = face_of(c);
    }
  }
  if (dead_.empty()) dead_.assign(faces_.size(), 0);
  // T_j takes the slot of S_a+j (same outer ring edge); a missing one takes
  // a spare from S_a / S_a-1; what is left dies.
  uint32_t spare[2] = {slot[0], slot[k - 1]};
  uint32_t fan_slot[kMaxPatchValence];
  for (uint32_t j = 1; j + 1 < k; ++j) {
    if (slot[j] != kNone) {
      fan_slot[j] = slot[j];
    } else if (spare[0] != kNone) {
      fan_slot[j] = spare[0];
      spare[0] = kNone;
    } else {
      fan_slot[j] = spare[1];
      spare[1] = kNone;
    }
  }
  for (uint32_t j = 1; j + 1 < k; ++j) {
    const uint32_t f = fan_slot[j];
    set_face(f, {R(0), R(j), R(j + 1)});
    const uint32_t b = 3 * f;
    set_opposite(b, o[j]);
    if (o[j] != kNone) set_opposite(o[j], b);
    if (j == k - 2) {
      set_opposite(b + 1, o[k - 1]);
      if (o[k - 1] != kNone) set_opposite(o[k - 1], b + 1);
    } else {
      set_opposite(b + 1, 3 * fan_slot[j + 1] + 2);
    }
    if (j == 1) {
      set_opposite(b + 2, o[0]);
      if (o[0] != kNone) set_opposite(o[0], b + 2);
    } else {
      set_opposite(b + 2, 3 * fan_slot[j - 1] + 1);
    }
  }
  for (uint32_t f : spare) {
    if (f == kNone) continue;
    dead_[f] = 1;
    for (int i = 0; i < 3; ++i) opposite_[3 * f + i] = kNone;
  }
  vertex_corner_[v] = kNone;
  auto in_star = [&](uint32_t c) {
    if (c == kNone) return false;
    const uint32_t f = face_of(c);
    for (uint32_t i = 0; i < k; ++i)
      if (slot[i] == f) return true;
    return false;
  };
  // A boundary vertex starts at the corner whose outgoing edge is open.
  if (o[0] == kNone || in_star(vertex_corner_[R(0)])) vertex_corner_[R(0)] = 3 * fan_slot[1];
  for (uint32_t j = 1; j < k; ++j) {
    const uint32_t u = R(j);
    if (j + 1 < k) {
      if (o[j] == kNone || in_star(vertex_corner_[u])) vertex_corner_[u] = 3 * fan_slot[j] + 1;
    } else {
      // R_a-1 sits only in T_k-2 (corner 2); its outgoing ring edge goes to the apex.
      if (o[k - 1] == kNone || in_star(vertex_corner_[u]))
        vertex_corner_[u] = 3 * fan_slot[k - 2] + 2;
    }
  }
}

// 108 lines in one function on purpose: it runs for every vertex a decoder
// inserts (13 % of a decode's instructions), and its phases — the outer
// corners of the ring edges, the face slots, the star faces (interior fast
// path or general loop), the vertex corners of the ring — share the
// stack arrays o[] and slot[]; the comments mark them.
uint32_t EditableMesh::insert_vertex(const std::vector<uint32_t>& ring,
                                     const std::vector<uint32_t>& fan_corners, uint32_t open,
                                     Vec3i position, std::vector<uint32_t>* touched) {
  const uint32_t k = static_cast<uint32_t>(ring.size());
  const uint32_t v = static_cast<uint32_t>(positions_.size());
  positions_.push_back(position);
  vertex_corner_.push_back(kNone);
  boundary_.push_back(open == kNone ? 0 : 1);

  uint32_t o[kMaxPatchValence], slot[kMaxPatchValence];
  // Outer corners of ring edges e_i = (R_i, R_i+1).
  for (uint32_t j = 1; j + 1 < k; ++j) {
    o[j] = opposite_[fan_corners[j - 1]];
    slot[j] = face_of(fan_corners[j - 1]);
  }
  o[0] = opposite_[prev(fan_corners[0])];
  o[k - 1] = opposite_[next(fan_corners[k - 3])];
  // Star face S_i = (v, R_i, R_i+1) for every i but `open`. S_j reuses fan
  // slot T_j; S_0 and S_k-1 take the slot freed by the open face, if any,
  // then new slots at the end.
  uint32_t first_new = static_cast<uint32_t>(faces_.size());
  uint32_t appended = 0;
  uint32_t freed = kNone;
  if (open != kNone && open >= 1 && open + 1 < k) {
    freed = slot[open];
    slot[open] = kNone;
  }
  slot[0] = slot[k - 1] = kNone;
  for (uint32_t i : {0u, k - 1}) {
    if (i == open) continue;
    if (freed != kNone) {
      slot[i] = freed;
      freed = kNone;
    } else {
      slot[i] = first_new + appended++;
    }
  }
  faces_.resize(first_new + appended);
  opposite_.resize(3 * (first_new + appended), kNone);
  if (!dead_.empty()) dead_.resize(first_new + appended, 0);

  if (open == kNone) {
    // Interior (nearly every insertion): no face is skipped, and the ring
    // and slot arrays are extended by one entry each way so the loop needs
    // no wrap tests. Same writes in the same order as the general loop.
    uint32_t ring_ext[kMaxPatchValence + 1], slot_ext[kMaxPatchValence + 2];
    for (uint32_t i = 0; i < k; ++i) {
      ring_ext[i] = ring[i];
      slot_ext[i + 1] = slot[i];
    }
    ring_ext[k] = ring[0];
    slot_ext[0] = slot[k - 1];
    slot_ext[k + 1] = slot[0];
    Triangle* faces = faces_.data();
    uint32_t* opposite = opposite_.data();
    for (uint32_t i = 0; i < k; ++i) {
      const uint32_t f = slot_ext[i + 1];
      faces[f] = {v, ring_ext[i], ring_ext[i + 1]};
      const uint32_t b = 3 * f;
      opposite[b] = o[i];
      if (o[i] != kNone) opposite[o[i]] = b;
      opposite[b + 1] = 3 * slot_ext[i + 2] + 2;
      opposite[b + 2] = 3 * slot_ext[i] + 1;
    }
    if (touched) touched->insert(touched->end(), slot_ext + 1, slot_ext + 1 + k);
  } else {
    // Ring indices wrap with compares, not `% k`: a division by a variable
    // costs tens of cycles, and this loop runs for every inserted vertex.
    for (uint32_t i = 0; i < k; ++i) {
      if (i == open) continue;
      const uint32_t f = slot[i];
      const uint32_t after = i + 1 == k ? 0 : i + 1, before = i == 0 ? k - 1 : i - 1;
      set_face(f, {v, ring[i], ring[after]});
      const uint32_t b = 3 * f;
      set_opposite(b, o[i]);
      if (o[i] != kNone) set_opposite(o[i], b);
      set_opposite(b + 1, after == open ? kNone : 3 * slot[after] + 2);
      set_opposite(b + 2, before == open ? kNone : 3 * slot[before] + 1);
      if (touched) touched->push_back(f);
    }
  }
  // The new vertex starts at the face after its open edge (any face if interior).
  vertex_corner_[v] = open == kNone ? 3 * slot[0] : 3 * slot[open + 1 == k ? 0 : open + 1];
  uint32_t fan_face[kMaxPatchValence];
  // A 64-bit filter of the fan's face ids (bit f % 64): most start corners
  // lie outside the fan, and the filter says so without the scan.
  uint64_t fan_filter = 0;
  for (uint32_t j = 0; j + 2 < k; ++j) {
    fan_face[j] = face_of(fan_corners[j]);
    fan_filter |= uint64_t(1) << (fan_face[j] & 63u);
  }
  auto in_fan = [&](uint32_t c) {
    if (c == kNone) return false;
    const uint32_t f = face_of(c);
    if (!((fan_filter >> (f & 63u)) & 1u)) return false;
    for (uint32_t j = 0; j + 2 < k; ++j)
      if (fan_face[j] == f) return true;
    return false;
  };
  for (uint32_t i = 0; i < k; ++i) {
    const uint32_t u = ring[i];
    if (i == open) {
      // Its outgoing boundary edge is now (R_i, v), in S_i-1 at corner 2.
      set_vertex_corner(u, 3 * slot[i == 0 ? k - 1 : i - 1] + 2);
    } else if (o[i] == kNone || in_fan(vertex_corner_[u])) {
      set_vertex_corner(u, 3 * slot[i] + 1);
    }
  }
  return v;
}

std::vector<Triangle> EditableMesh::live_faces() const {
  std::vector<Triangle> out;
  out.reserve(faces_.size());
  for (uint32_t f = 0; f < faces_.size(); ++f)
    if (!face_dead(f)) out.push_back(faces_[f]);
  return out;
}

}  // namespace meshstream
