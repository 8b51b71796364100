// Patch geometry: see patch_geometry.h.
#include "common/codec/patch_geometry.h"

#include <algorithm>

#include "common/codec/stream_format.h"

namespace meshstream {

bool resolve_patch(const EditableMesh& mesh, uint32_t apex, const std::vector<uint32_t>& star_ring,
                   const std::vector<uint32_t>& star_corners, uint32_t r, uint32_t k,
                   ResolvedPatch& out) {
  const uint32_t faces = static_cast<uint32_t>(star_corners.size());
  if (k < 3 || k > kMaxInsertedValence || r >= faces) return false;
  const uint32_t fan = k - 2;
  if (mesh.is_boundary(apex)) {
    if (r + fan > faces) return false;  // would cross the boundary
  } else {
    if (fan + 1 > faces) return false;  // k-1 ring entries must be distinct
  }
  out.ring.resize(k);
  out.fan_corners.resize(fan);
  out.ring[0] = apex;
  // r < faces and fan <= faces, so one subtraction wraps (no division).
  uint32_t i = r;
  for (uint32_t j = 0; j < fan; ++j) {
    out.fan_corners[j] = star_corners[i];
    out.ring[j + 1] = star_ring[i];
    if (++i == faces) i = 0;
  }
  const size_t last = r + fan;
  out.ring[k - 1] = star_ring[last < star_ring.size() ? last : last - star_ring.size()];
  return true;
}

uint32_t mark_taken_faces(const RefinementState& s, const std::vector<uint32_t>& star_ring,
                          uint32_t faces, std::vector<uint8_t>& used) {
  used.resize(faces);
  if (faces == 0) return 0;
  const size_t n = star_ring.size();
  // Face i joins ring entries i and i+1 (the last wraps to 0 when interior).
  const uint32_t* layer = s.vertex_layer.data();
  const uint32_t* ring = star_ring.data();
  const uint32_t current = s.layer;
  uint8_t* out = used.data();
  const bool first_new = layer[ring[0]] == current;
  bool prev_new = first_new;
  uint32_t free_faces = 0;
  // Faces whose far entry is ring[i + 1] (all but an interior star's last,
  // which closes onto ring[0]), then that last one: no wrap test per face.
  const uint32_t open_faces = faces < n ? faces : static_cast<uint32_t>(n) - 1;
  for (uint32_t i = 0; i < open_faces; ++i) {
    const bool next_new = layer[ring[i + 1]] == current;
    const bool taken = prev_new || next_new;
    out[i] = taken ? 1 : 0;
    free_faces += taken ? 0 : 1;
    prev_new = next_new;
  }
  for (uint32_t i = open_faces; i < faces; ++i) {
    const bool taken = prev_new || first_new;
    out[i] = taken ? 1 : 0;
    free_faces += taken ? 0 : 1;
    prev_new = first_new;
  }
  return free_faces;
}

uint32_t score_patch_starts_raw(const EditableMesh& mesh, uint32_t apex,
                                const std::vector<uint32_t>& star_ring,
                                const std::vector<uint8_t>& used, uint32_t k,
                                StartScratch& scratch) {
  const uint32_t faces = static_cast<uint32_t>(used.size());
  const uint32_t fan = k - 2;
  const bool boundary = mesh.is_boundary(apex);
  if (k < 3 || faces == 0 || (!boundary && fan + 1 > faces) || (boundary && fan > faces)) return 0;
  const Vec3i* p = mesh.positions().data();
  auto l2 = [&](uint32_t a, uint32_t b) {
    const int64_t dx = int64_t(p[a].x) - p[b].x, dy = int64_t(p[a].y) - p[b].y,
                  dz = int64_t(p[a].z) - p[b].z;
    return dx * dx + dy * dy + dz * dz;
  };
  int64_t* edge = scratch.edge;
  int64_t* score = scratch.score;
  uint32_t* out = scratch.start;
  uint32_t n = 0;
  const uint32_t last_start = boundary ? faces - fan : faces - 1;
  const size_t ring_n = star_ring.size();
  if (k == 3) {
    for (uint32_t r = 0; r <= last_start; ++r) {
      if (used[r]) continue;
      const uint32_t b = r + 1 < ring_n ? r + 1 : 0;
      score[n] = l2(star_ring[r], star_ring[b]);
      out[n++] = r;
    }
  } else {
    // Squared apex edge lengths, then a sliding sum over the k-3 diagonals
    // of each run (ring entries r+1 .. r+k-3). Indices past the last face
    // wrap to the start: `edge` holds the first `fan` lengths again after
    // the last (room for 2 * faces), and `used` is read through a wrapped
    // index only at the run's far end.
    for (uint32_t i = 0; i < faces; ++i) edge[i] = l2(apex, star_ring[i]);
    for (uint32_t i = 0; i < fan; ++i) edge[faces + i] = edge[i];
    int64_t window = 0;
    for (uint32_t j = 1; j < fan; ++j) window += edge[j];
    uint32_t used_in_run = 0;
    for (uint32_t j = 0; j < fan; ++j) used_in_run += used[j];
    uint32_t far = fan < faces ? fan : 0;  // (r + fan) wrapped, maintained without division
    for (uint32_t r = 0; r <= last_start; ++r) {
      if (used_in_run == 0) {
        score[n] = window;
        out[n++] = r;
      }
      // Slide the run one face on: drop face r and diagonal r+1, add the next.
      window += edge[r + fan] - edge[r + 1];
      used_in_run += used[far];
      used_in_run -= used[r];
      if (++far == faces) far = 0;
    }
  }
  return n;
}

namespace {

// The same into a vector (the encoder's side).
void score_patch_starts(const EditableMesh& mesh, uint32_t apex,
                        const std::vector<uint32_t>& star_ring, const std::vector<uint8_t>& used,
                        uint32_t k, std::vector<uint32_t>& out, StartScratch& scratch) {
  const uint32_t n = score_patch_starts_raw(mesh, apex, star_ring, used, k, scratch);
  out.assign(scratch.start, scratch.start + n);
}

}  // namespace

void rank_patch_starts(const EditableMesh& mesh, uint32_t apex,
                       const std::vector<uint32_t>& star_ring, const std::vector<uint8_t>& used,
                       uint32_t k, std::vector<uint32_t>& out) {
  StartScratch scratch(static_cast<uint32_t>(used.size()));
  score_patch_starts(mesh, apex, star_ring, used, k, out, scratch);
  sort_patch_starts(out, scratch.score);
}

void rank_patch_starts(const EditableMesh& mesh, uint32_t apex,
                       const std::vector<uint32_t>& star_ring, const std::vector<uint8_t>& used,
                       uint32_t k, std::vector<uint32_t>& out, std::vector<int64_t>& scores) {
  StartScratch scratch(static_cast<uint32_t>(used.size()));
  score_patch_starts(mesh, apex, star_ring, used, k, out, scratch);
  sort_patch_starts(out, scratch.score);
  scores.assign(scratch.score, scratch.score + out.size());
}

uint32_t select_patch_start(const EditableMesh& mesh, uint32_t apex,
                            const std::vector<uint32_t>& star_ring,
                            const std::vector<uint8_t>& used, uint32_t k, uint32_t rank,
                            std::vector<uint32_t>& scratch_starts) {
  StartScratch scratch(static_cast<uint32_t>(used.size()));
  std::vector<uint32_t>& starts = scratch_starts;
  score_patch_starts(mesh, apex, star_ring, used, k, starts, scratch);
  if (rank >= starts.size()) return kNone;
  if (rank == 0) {
    // The first of the best: strictly larger wins, so ties keep the smaller r
    // (starts are in increasing r), as the stable sort orders them.
    size_t best = 0;
    for (size_t i = 1; i < starts.size(); ++i)
      if (scratch.score[i] > scratch.score[best]) best = i;
    return starts[best];
  }
  sort_patch_starts(starts, scratch.score);
  return starts[rank];
}

void patch_boundary_edges(const EditableMesh& mesh, const ResolvedPatch& patch,
                          std::vector<uint32_t>& out) {
  out.clear();
  const uint32_t k = static_cast<uint32_t>(patch.ring.size());
  const auto& fc = patch.fan_corners;
  if (mesh.opposite(EditableMesh::prev(fc[0])) == kNone) out.push_back(0);
  for (uint32_t j = 1; j + 1 < k; ++j)
    if (mesh.opposite(fc[j - 1]) == kNone) out.push_back(j);
  if (mesh.opposite(EditableMesh::next(fc[k - 3])) == kNone) out.push_back(k - 1);
}

uint32_t apply_patch(RefinementState& state, const ResolvedPatch& patch, uint32_t open,
                     Vec3i position, std::vector<uint32_t>* touched) {
  const uint32_t v =
      state.mesh.insert_vertex(patch.ring, patch.fan_corners, open, position, touched);
  const uint32_t apex = patch.ring[0];
  const uint32_t k = static_cast<uint32_t>(patch.ring.size());
  state.vertices.push_back({state.vertices[apex].next, state.layer, k});
  state.vertex_layer.push_back(state.layer);
  state.vertex_shift.push_back(0);  // the geometry overload sets it
  state.vertices[apex].next = v;
  // Valences: the apex trades its k-3 diagonals for v, R_1 and R_k-1 gain v,
  // and the ends of a re-opened boundary edge lose each other.
  // Every ring vertex now has one or two faces holding v (none across the
  // re-opened boundary edge): count them as taken in this layer.
  for (uint32_t i = 0; i < k; ++i) {
    RefinementState::VertexEntry& e = state.vertices[patch.ring[i]];
    if (e.taken_layer != state.layer) {
      e.taken_layer = state.layer;
      e.taken = 0;
    }
    if (open == kNone) {
      e.taken += 2;  // interior: both faces at R_i hold v
    } else {
      const uint32_t before = i == 0 ? k - 1 : i - 1;  // no division: this runs per ring vertex
      e.taken += (i != open ? 1u : 0u) + (before != open ? 1u : 0u);
    }
  }
  state.vertices[apex].valence = state.vertices[apex].valence + 4 - k;
  state.vertices[patch.ring[1]].valence += 1;
  state.vertices[patch.ring[k - 1]].valence += 1;
  if (open != kNone) {
    state.vertices[patch.ring[open]].valence -= 1;
    state.vertices[patch.ring[open + 1 == k ? 0 : open + 1]].valence -= 1;
  }
  return v;
}

uint32_t apply_patch(RefinementState& state, const ResolvedPatch& patch, uint32_t open,
                     const VertexGeometry& geometry, std::vector<uint32_t>* touched) {
  state.geometry.push_back(geometry);
  const uint32_t v =
      apply_patch(state, patch, open, reconstruct(geometry, state.max_coordinate), touched);
  state.vertex_shift[v] = geometry.shift;
  return v;
}

}  // namespace meshstream
