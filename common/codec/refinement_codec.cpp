// Refinement records: see refinement_codec.h for the layout and why.
#include "common/codec/refinement_codec.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

#include "common/codec/byte_io.h"
#include "common/codec/decimate.h"

namespace meshstream {

namespace {

Status bad(const std::string& what) { return make_error(ErrorCode::kCorrupt, what); }

}  // namespace

Result<RefinementState> RefinementState::from_base(std::vector<Vec3i> positions,
                                                   std::vector<Triangle> faces, int quant_bits) {
  const uint32_t n = static_cast<uint32_t>(positions.size());
  auto mesh = EditableMesh::build(std::move(positions), std::move(faces));
  if (!mesh) return tl::unexpected(mesh.error());
  RefinementState s;
  s.mesh = std::move(*mesh);
  s.vertices.resize(n);
  s.vertex_layer.assign(n, 0);
  s.vertex_shift.assign(n, 0);
  for (uint32_t v = 0; v < n; ++v) s.vertices[v].next = v + 1 < n ? v + 1 : kNone;
  s.order_head = n > 0 ? 0 : kNone;
  std::vector<uint32_t> ring, corners;
  for (uint32_t v = 0; v < n; ++v) {
    s.mesh.star(v, ring, corners);
    s.vertices[v].valence = static_cast<uint32_t>(ring.size());
  }
  s.max_coordinate = (int32_t(1) << quant_bits) - 1;
  s.geometry.resize(n);
  for (uint32_t v = 0; v < n; ++v) {
    s.geometry[v].anchor = s.mesh.positions()[v];
    s.geometry[v].normal_axis = kBaseVertexAxis;
  }
  return s;
}

Result<RefinementState> RefinementState::from_coarse_base(const std::vector<Vec3i>& coarse,
                                                          std::vector<Triangle> faces,
                                                          int quant_bits, int base_shift) {
  const int32_t max = (int32_t(1) << quant_bits) - 1;
  std::vector<VertexGeometry> geometry(coarse.size());
  std::vector<Vec3i> positions(coarse.size());
  for (size_t v = 0; v < coarse.size(); ++v) {
    VertexGeometry& g = geometry[v];
    for (int a = 0; a < 3; ++a) g.anchor[a] = int32_t(uint32_t(coarse[v][a]) << base_shift);
    g.shift = static_cast<uint8_t>(base_shift);
    g.normal_axis = kBaseVertexAxis;
    positions[v] = reconstruct(g, max);
  }
  auto s = from_base(std::move(positions), std::move(faces), quant_bits);
  if (!s) return s;
  s->geometry = std::move(geometry);
  s->vertex_shift.assign(s->vertices.size(), static_cast<uint8_t>(base_shift));
  return s;
}

bool resolve_patch(const EditableMesh& mesh, uint32_t apex, const std::vector<uint32_t>& star_ring,
                   const std::vector<uint32_t>& star_corners, uint32_t r, uint32_t k,
                   ResolvedPatch& out) {
  const uint32_t faces = static_cast<uint32_t>(star_corners.size());
  if (k < 3 || k > kMaxRemovalValence || r >= faces) return false;
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

void encode_coarse_residual(RefinementModels& models, RangeEncoder& enc, const ResidualContext& ctx,
                            Vec3i actual, Vec3i predicted, int shift, VertexGeometry& out) {
  const int bucket = std::max(ctx.scale - shift, 0);
  out = VertexGeometry{};
  out.anchor = predicted;
  out.shift = static_cast<uint8_t>(shift);
  out.normal_axis = static_cast<uint8_t>(ctx.axis[0]);
  for (int role = 0; role < 3; ++role) {
    const int a = ctx.axis[role];
    const int32_t r = actual[a] - predicted[a];
    const uint32_t mag = uint32_t(std::abs(r)) >> shift;
    int32_t q = r < 0 ? -int32_t(mag) : int32_t(mag);
    out.mag[a] = mag;
    if (mag > 0 && r < 0) out.negative |= uint8_t(1u << a);
    if (role == 0 && ctx.flip) q = -q;
    models.residual[bucket][role].encode(enc, q);
  }
}

namespace {

// The bodies of decode_coarse_residual and decode_start_rank, forced inline
// into apply_refinement_record so its range decoder stays in registers
// (see MESHSTREAM_DECODE_INLINE in range_coder.h).
MESHSTREAM_DECODE_INLINE bool decode_residual_inline(RefinementModels& models, RangeDecoder& dec,
                                                     const ResidualContext& ctx, Vec3i predicted,
                                                     int shift, int32_t max_coordinate,
                                                     VertexGeometry& out) {
  const int bucket = std::max(ctx.scale - shift, 0);
  out = VertexGeometry{};
  out.anchor = predicted;
  out.shift = static_cast<uint8_t>(shift);
  out.normal_axis = static_cast<uint8_t>(ctx.axis[0]);
  for (int role = 0; role < 3; ++role) {
    const int a = ctx.axis[role];
    int64_t q = models.residual[bucket][role].decode(dec);
    if (role == 0 && ctx.flip) q = -q;
    const int64_t mag = q < 0 ? -q : q;
    if ((mag << shift) > int64_t(max_coordinate)) return false;
    if (shift == 0) {
      const int64_t value = int64_t(predicted[a]) + q;
      if (value < 0 || value > max_coordinate) return false;
    }
    out.mag[a] = static_cast<uint32_t>(mag);
    if (q < 0) out.negative |= uint8_t(1u << a);
  }
  return true;
}

MESHSTREAM_DECODE_INLINE uint32_t decode_start_rank_inline(RefinementModels& m, RangeDecoder& dec,
                                                           uint32_t k) {
  const uint32_t rank = m.start_rank[std::min(k - 3, 5u)].decode(dec);
  return rank < 15 ? rank : 15 + m.start_rank_big.decode(dec);
}

// predict_insertion (refinement_codec.h), forced inline into the decoder's
// record loop. One pass over the ring: the sums run in ring order, and the
// normal skips only the two cross products that are zero (those with the
// apex itself, whose offset from the apex is 0). The divisions by k are
// 32-bit when the dividends fit (they do for grid coordinates < 2^20 and
// k <= 16), which gives the same quotients as the 64-bit ones.
MESHSTREAM_DECODE_INLINE void predict_insertion_inline(const RefinementState& s,
                                                       const std::vector<uint32_t>& ring,
                                                       int min_shift, InsertionPrediction& out) {
  const Vec3i* p = s.mesh.positions().data();
  const uint8_t* vertex_shift = s.vertex_shift.data();
  const size_t k = ring.size();
  const Vec3i o = p[ring[0]];
  int64_t sx = o.x, sy = o.y, sz = o.z;
  int shift = std::max<int>(min_shift, vertex_shift[ring[0]]);
  int64_t total = 0;
  int64_t n0 = 0, n1 = 0, n2 = 0;
  int64_t px = 0, py = 0, pz = 0;  // the previous ring vertex's offset from the apex
  Vec3i a = o;
  for (size_t i = 1; i < k; ++i) {
    const uint32_t u = ring[i];
    const Vec3i b = p[u];
    sx += b.x;
    sy += b.y;
    sz += b.z;
    shift = std::max<int>(shift, vertex_shift[u]);
    total +=
        std::abs(int64_t(a.x) - b.x) + std::abs(int64_t(a.y) - b.y) + std::abs(int64_t(a.z) - b.z);
    const int64_t dx = int64_t(b.x) - o.x, dy = int64_t(b.y) - o.y, dz = int64_t(b.z) - o.z;
    n0 += py * dz - pz * dy;
    n1 += pz * dx - px * dz;
    n2 += px * dy - py * dx;
    px = dx;
    py = dy;
    pz = dz;
    a = b;
  }
  total +=
      std::abs(int64_t(a.x) - o.x) + std::abs(int64_t(a.y) - o.y) + std::abs(int64_t(a.z) - o.z);

  const int64_t sum[3] = {sx, sy, sz};
  const int64_t kk = static_cast<int64_t>(k);
  for (int c = 0; c < 3; ++c) {
    const int64_t num = sum[c] + kk / 2;
    out.predicted[c] = num >= 0 && num <= int64_t(UINT32_MAX)
                           ? static_cast<int32_t>(uint32_t(num) / uint32_t(k))
                           : static_cast<int32_t>(num / kk);
  }
  const uint64_t mean = (uint64_t(total) <= UINT32_MAX ? uint64_t(uint32_t(total) / uint32_t(k))
                                                       : uint64_t(total) / k) +
                        1;
  ResidualContext& ctx = out.ctx;
  ctx = ResidualContext{};
  // log2 of the mean L1 edge length, in integers: octave buckets (finer
  // buckets measured slightly worse: too little data per model).
  ctx.scale = std::clamp(63 - __builtin_clzll(mean), 0, kScaleContexts - 1);
  // Axes by |normal component|, largest first; ties keep axis order.
  const int64_t n[3] = {n0, n1, n2};
  const int64_t m[3] = {std::abs(n0), std::abs(n1), std::abs(n2)};
  auto before = [&](int x, int y) { return m[x] > m[y] || (m[x] == m[y] && x < y); };
  int* ax = ctx.axis;
  if (before(ax[1], ax[0])) std::swap(ax[0], ax[1]);
  if (before(ax[2], ax[1])) std::swap(ax[1], ax[2]);
  if (before(ax[1], ax[0])) std::swap(ax[0], ax[1]);
  ctx.flip = n[ctx.axis[0]] < 0;
  out.shift = shift;
}

}  // namespace

bool decode_coarse_residual(RefinementModels& models, RangeDecoder& dec, const ResidualContext& ctx,
                            Vec3i predicted, int shift, int32_t max_coordinate,
                            VertexGeometry& out) {
  return decode_residual_inline(models, dec, ctx, predicted, shift, max_coordinate, out);
}

void predict_insertion(const RefinementState& s, const std::vector<uint32_t>& ring, int min_shift,
                       InsertionPrediction& out) {
  predict_insertion_inline(s, ring, min_shift, out);
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

namespace {

// Scratch of the start scoring: on the stack for ordinary stars, on the
// heap for huge ones. The decoder keeps one for a whole record (prepare per
// star) instead of building one per patch.
struct StartScratch {
  static constexpr uint32_t kSmall = 64;
  int64_t edge_small[2 * kSmall], score_small[kSmall];  // edge: wrapped copy after the end
  uint32_t start_small[kSmall];
  std::vector<int64_t> edge_big, score_big;
  std::vector<uint32_t> start_big;
  int64_t* edge = edge_small;
  int64_t* score = score_small;
  uint32_t* start = start_small;
  StartScratch() = default;
  explicit StartScratch(uint32_t faces) { prepare(faces); }
  StartScratch(const StartScratch&) = delete;
  StartScratch& operator=(const StartScratch&) = delete;
  void prepare(uint32_t faces) {
    if (faces > kSmall) {
      if (score_big.size() < faces) {
        edge_big.resize(2 * size_t(faces));
        score_big.resize(faces);
        start_big.resize(faces);
      }
      edge = edge_big.data();
      score = score_big.data();
      start = start_big.data();
    } else {
      edge = edge_small;
      score = score_small;
      start = start_small;
    }
  }
};

// The candidate starts of rank_patch_starts in increasing r into
// scratch.start, with their scores in scratch.score (score[i] belongs to
// start[i]), unsorted; returns their number. The scratch is prepared for
// used.size() faces. Raw arrays: a push_back per candidate cost more than
// the scoring of it.
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

// The same into a vector (the encoder's side).
void score_patch_starts(const EditableMesh& mesh, uint32_t apex,
                        const std::vector<uint32_t>& star_ring, const std::vector<uint8_t>& used,
                        uint32_t k, std::vector<uint32_t>& out, StartScratch& scratch) {
  const uint32_t n = score_patch_starts_raw(mesh, apex, star_ring, used, k, scratch);
  out.assign(scratch.start, scratch.start + n);
}

// Larger score first, ties by r (stable insertion sort: runs are few).
void sort_patch_starts(uint32_t* out, size_t n, int64_t* score) {
  for (size_t i = 1; i < n; ++i) {
    const int64_t sc = score[i];
    const uint32_t r = out[i];
    size_t j = i;
    while (j > 0 && score[j - 1] < sc) {
      score[j] = score[j - 1];
      out[j] = out[j - 1];
      --j;
    }
    score[j] = sc;
    out[j] = r;
  }
}

void sort_patch_starts(std::vector<uint32_t>& out, int64_t* score) {
  sort_patch_starts(out.data(), out.size(), score);
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

void encode_start_rank(RefinementModels& m, RangeEncoder& enc, uint32_t k, uint32_t rank) {
  BitTreeModel<4>& tree = m.start_rank[std::min(k - 3, 5u)];
  if (rank < 15) {
    tree.encode(enc, rank);
  } else {
    tree.encode(enc, 15);
    m.start_rank_big.encode(enc, rank - 15);
  }
}

void encode_start_rank3(RefinementModels& m, RangeEncoder& enc, uint32_t context, size_t candidates,
                        uint32_t rank) {
  if (candidates <= 1) return;
  BitTreeModel<4, BitModelV>& tree = m.start_rank3[context];
  if (rank < 15) {
    tree.encode(enc, rank);
  } else {
    tree.encode(enc, 15);
    m.start_rank_big3.encode(enc, rank - 15);
  }
}

uint32_t decode_start_rank(RefinementModels& m, RangeDecoder& dec, uint32_t k) {
  return decode_start_rank_inline(m, dec, k);
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

void write_record_header(const RecordHeader& header, std::vector<uint8_t>& out, uint8_t format) {
  out.push_back(header.starts_layer ? kRecordStartsLayer : 0);
  put_varint(out, header.walk_steps);
  put_varint(out, header.insertions);
  if (format >= 2) put_varint(out, header.min_shift);
}

Status apply_plane_record(RefinementState& state, std::span<const uint8_t> payload,
                          AppliedRecord& applied) {
  applied.added_vertices.clear();
  applied.touched_faces.clear();
  applied.moved_vertices.clear();
  size_t pos = 1;
  uint32_t first = 0, count = 0;
  if (state.format < 2) return bad("plane record in a stream of refinement format 1");
  if (!get_varint(payload, pos, first) || !get_varint(payload, pos, count)) {
    return bad("plane record header is cut short or malformed");
  }
  const uint32_t n = state.mesh.vertex_count();
  if (count == 0 || first >= n || count > n - first) {
    return bad("plane record covers vertices " + std::to_string(first) + " + " +
               std::to_string(count) + " of a mesh of " + std::to_string(n));
  }
  RangeDecoder dec(payload.subspan(pos));
  PlaneBitReader io{dec};
  uint8_t prev_new = 0;
  for (uint32_t v = first; v < first + count; ++v) {
    VertexGeometry& g = state.geometry[v];
    if (g.shift == 0) continue;
    if (!plane_step(state.geometry_models, io, g, prev_new, state.max_coordinate)) {
      return bad("plane record gives vertex " + std::to_string(v) + " a residual beyond the grid");
    }
    state.vertex_shift[v] = g.shift;
    if (g.shift == 0 && g.normal_axis != kBaseVertexAxis) {
      for (int a = 0; a < 3; ++a) {
        const int64_t value =
            int64_t(g.anchor[a]) + ((g.negative >> a) & 1 ? -int64_t(g.mag[a]) : int64_t(g.mag[a]));
        if (value < 0 || value > state.max_coordinate) {
          return bad("plane record puts vertex " + std::to_string(v) +
                     " outside the quantization grid");
        }
      }
    }
    if (dec.exhausted_badly()) return bad("plane record data ends early");
    const Vec3i p = reconstruct(g, state.max_coordinate);
    if (!(p == state.mesh.positions()[v])) {
      state.mesh.set_position(v, p);
      applied.moved_vertices.push_back(v);
    }
  }
  if (dec.exhausted_badly()) return bad("plane record data ends early");
  return {};
}

std::vector<uint8_t> write_plane_record(RefinementState& state, uint32_t first, uint32_t count,
                                        const std::vector<Vec3i>& residuals) {
  std::vector<uint8_t> out;
  out.push_back(kRecordPlane);
  put_varint(out, first);
  put_varint(out, count);
  RangeEncoder enc;
  uint8_t prev_new = 0;
  for (uint32_t v = first; v < first + count; ++v) {
    VertexGeometry& g = state.geometry[v];
    if (g.shift == 0) continue;
    PlaneBitWriter io{enc, residuals[v]};
    plane_step(state.geometry_models, io, g, prev_new, state.max_coordinate);
    state.vertex_shift[v] = g.shift;
    state.mesh.set_position(v, reconstruct(g, state.max_coordinate));
  }
  const std::vector<uint8_t> coded = enc.finish();
  out.insert(out.end(), coded.begin(), coded.end());
  return out;
}

namespace {

MESHSTREAM_DECODE_INLINE uint32_t decode_start_rank_inline3(RefinementModels& m, RangeDecoder& dec,
                                                            uint32_t context) {
  const uint32_t rank = m.start_rank3[context].decode(dec);
  return rank < 15 ? rank : 15 + m.start_rank_big3.decode(dec);
}

// Format 3's decoder side of the start: the candidates are scored first
// (their number and the lead of the best score are the rank's context),
// then the rank is read (nothing for a single candidate) and its start
// picked, the best by a linear scan. kNone when the rank is out of range.
template <class DecodeRank>
MESHSTREAM_DECODE_INLINE uint32_t select_patch_start3(const EditableMesh& mesh, uint32_t apex,
                                                      const std::vector<uint32_t>& star_ring,
                                                      const std::vector<uint8_t>& used, uint32_t k,
                                                      StartScratch& scratch,
                                                      DecodeRank&& decode_rank, uint32_t& rank) {
  scratch.prepare(static_cast<uint32_t>(used.size()));
  const size_t n = score_patch_starts_raw(mesh, apex, star_ring, used, k, scratch);
  const uint32_t* starts = scratch.start;
  if (n == 0) {
    rank = 0;
    return kNone;
  }
  // The best (first of the largest: ties keep the smaller r, as the stable
  // sort orders them) and the second best score.
  size_t best = 0;
  int64_t second = -1;
  for (size_t i = 1; i < n; ++i) {
    const int64_t sc = scratch.score[i];
    if (sc > scratch.score[best]) {
      second = scratch.score[best];
      best = i;
    } else if (sc > second) {
      second = sc;
    }
  }
  rank = n > 1 ? decode_rank(start_rank_context(k, n, scratch.score[best], second)) : 0;
  if (rank >= n) return kNone;
  if (rank == 0) return starts[best];
  sort_patch_starts(scratch.start, n, scratch.score);
  return scratch.start[rank];
}

}  // namespace

// The range-coded block of a structure record, after its header: one
// instance per model family (V: format 3's models), so the decoding loop,
// inlined whole, holds no per-symbol format branches.
template <bool V>
Status decode_structure_block(RefinementState& state, std::span<const uint8_t> block,
                              const RecordHeader& h, uint32_t expected_vertices,
                              uint32_t expected_faces, AppliedRecord& applied) {
  RangeDecoder dec(block);
  RefinementModels& m = state.models;
  EditableMesh& mesh = state.mesh;
  std::vector<uint32_t> star_ring, star_corners;
  std::vector<ResolvedPatch> patches;
  std::vector<VertexGeometry> positions;
  std::vector<uint32_t> opens, open_edges, candidates;
  std::vector<uint8_t> used_faces;
  StartScratch start_scratch;
  uint32_t inserted = 0;
  // On error the state is left half-applied: the caller discards it (the
  // decoder's output mesh is only updated after a record succeeds).
  auto fail = [&](const std::string& what) -> Status { return bad(what); };

  for (uint32_t step = 0; step < h.walk_steps; ++step) {
    while (state.cursor != kNone && state.vertices[state.cursor].layer == state.layer) {
      state.cursor = state.vertices[state.cursor].next;
    }
    if (state.cursor == kNone) return fail("refinement walk runs past the last vertex");
    const uint32_t u = state.cursor;
    state.cursor = state.vertices[u].next;
    // The order list jumps around memory: start loading what the next two
    // walk vertices need while this one is decoded (the entry and start
    // corner of the one after next, the first star face of the next, whose
    // entry and corner were asked for one step ago).
    if (state.cursor != kNone) {
      const uint32_t after = state.vertices[state.cursor].next;
      if (after != kNone) {
        __builtin_prefetch(&state.vertices[after]);
        mesh.prefetch_vertex(after);
      }
      mesh.prefetch_first_face(state.cursor);
    }
    const uint32_t free_faces = free_face_count(state, u);
    uint32_t count = 0;
    if (free_faces > 0) {
      if constexpr (V) {
        count = count_model3(state, u, free_faces).decode(dec);
        if (count == 3) count += m.patch_count_extra3.decode(dec);
      } else {
        count = m.patch_count[count_context(state, u, free_faces)].decode(dec);
        if (count == 3) count += m.patch_count_extra.decode(dec);
      }
    }
    state.last_count = count;
    if (count == 0) continue;
    mesh.star(u, star_ring, star_corners);
    // Positions (patch scores), start corners (insert_vertex) and entries
    // (apply_patch) of the ring are read after some bits are decoded: ask
    // for them now.
    for (uint32_t r : star_ring) {
      mesh.prefetch_vertex(r);
      __builtin_prefetch(&state.vertices[r]);
    }
    // So are the faces beyond the star's outer edges (insert_vertex links
    // the new faces to them), which are also in the stars of the ring
    // vertices the walk visits next. Their corners sit next to what star()
    // just read, so asking costs no wait.
    for (uint32_t c : star_corners) {
      const uint32_t o = mesh.opposite(c);
      if (o != kNone) mesh.prefetch_corner(o);
    }
    const uint32_t ring_size = static_cast<uint32_t>(star_ring.size());
    const uint32_t faces = static_cast<uint32_t>(star_corners.size());
    if (mark_taken_faces(state, star_ring, faces, used_faces) != free_faces) {
      // Both counts come from the state apply_patch keeps, whatever the
      // input: a mismatch is a bug here, not a bad stream.
      return make_error(ErrorCode::kInternal,
                        "free face counts disagree at vertex " + std::to_string(u));
    }
    if (count > free_faces || inserted + count > h.insertions) {
      return fail("vertex " + std::to_string(u) + " claims " + std::to_string(count) +
                  " patches, more than it or the record holds");
    }
    // Grown, never shrunk: a patch's ring and corner vectors keep their
    // storage from one walk vertex to the next (resizing down and up again
    // freed and reallocated them). Only the first `count` entries are used.
    if (patches.size() < count) {
      patches.resize(count);
      positions.resize(count);
      opens.resize(count);
    }
    uint32_t free_left = free_faces;
    for (uint32_t i = 0; i < count; ++i) {
      uint32_t k;
      if constexpr (V) {
        k = valence_model3(state, ring_size, free_left).decode(dec) + 3;
      } else {
        k = m.valence[std::min(ring_size, 12u)].decode(dec) + 3;
      }
      uint32_t rank = 0, r = kNone;
      if constexpr (!V) {
        // The rank depends only on k, so it is read first: the decoder then
        // needs only the start of that rank, most often the best one (a
        // linear scan), not the whole ordered list the encoder searches.
        rank = decode_start_rank_inline(m, dec, k);
        r = select_patch_start(mesh, u, star_ring, used_faces, k, rank, candidates);
      } else {
        r = select_patch_start3(
            mesh, u, star_ring, used_faces, k, start_scratch,
            [&](uint32_t context) __attribute__((always_inline)) {
              return decode_start_rank_inline3(m, dec, context);
            },
            rank);
      }
      free_left = free_left >= k - 2 ? free_left - (k - 2) : 0;
      if (r == kNone) {
        return fail("patch " + std::to_string(i) + " at vertex " + std::to_string(u) +
                    " (valence " + std::to_string(k) + ", start rank " + std::to_string(rank) +
                    ") does not fit its star of " + std::to_string(faces) + " faces");
      }
      if (!resolve_patch(mesh, u, star_ring, star_corners, r, k, patches[i])) {
        return fail("patch " + std::to_string(i) + " at vertex " + std::to_string(u) +
                    " does not fit");
      }
      for (uint32_t j = 0, f = r; j + 2 < k; ++j, f = f + 1 == faces ? 0 : f + 1) used_faces[f] = 1;
      opens[i] = kNone;
      patch_boundary_edges(mesh, patches[i], open_edges);
      if (!open_edges.empty()) {
        uint32_t choice;
        if constexpr (V) {
          choice = m.open_edge3.decode(dec);
        } else {
          choice = m.open_edge.decode(dec);
        }
        if (choice > open_edges.size()) {
          return fail("patch at vertex " + std::to_string(u) + " re-enters boundary edge " +
                      std::to_string(choice) + " of " + std::to_string(open_edges.size()));
        }
        if (choice > 0) opens[i] = open_edges[choice - 1];
      }
      InsertionPrediction prediction;
      predict_insertion_inline(state, patches[i].ring, static_cast<int>(h.min_shift), prediction);
      if (!decode_residual_inline(m, dec, prediction.ctx, prediction.predicted, prediction.shift,
                                  state.max_coordinate, positions[i])) {
        return fail("vertex position outside the quantization grid at vertex " + std::to_string(u));
      }
    }
    if (dec.exhausted_badly()) return fail("refinement record data ends early");
    for (uint32_t i = 0; i < count; ++i) {
      const uint32_t v =
          apply_patch(state, patches[i], opens[i], positions[i], &applied.touched_faces);
      applied.added_vertices.push_back(v);
    }
    inserted += count;
  }
  if (inserted != h.insertions) {
    return fail("refinement record holds " + std::to_string(inserted) +
                " insertions, its header says " + std::to_string(h.insertions));
  }
  if (dec.exhausted_badly()) return fail("refinement record data ends early");
  if (mesh.vertex_count() != expected_vertices || mesh.face_slot_count() != expected_faces) {
    return fail("refinement record yields " + std::to_string(mesh.vertex_count()) +
                " vertices and " + std::to_string(mesh.face_slot_count()) +
                " faces, the index says " + std::to_string(expected_vertices) + " and " +
                std::to_string(expected_faces));
  }
  return {};
}

Status apply_refinement_record(RefinementState& state, std::span<const uint8_t> payload,
                               uint32_t expected_vertices, uint32_t expected_faces,
                               AppliedRecord& applied) {
  applied.added_vertices.clear();
  applied.touched_faces.clear();
  applied.moved_vertices.clear();
  if (payload.empty()) return bad("empty refinement record");
  const uint8_t flags = payload[0];
  if (flags == kRecordPlane) {
    if (auto st = apply_plane_record(state, payload, applied); !st) return st;
    if (state.mesh.vertex_count() != expected_vertices ||
        state.mesh.face_slot_count() != expected_faces) {
      return bad("plane record where the index says the mesh grows");
    }
    return {};
  }
  if (flags > 1) return bad("unknown refinement record flags " + std::to_string(flags));
  size_t pos = 1;
  RecordHeader h;
  h.starts_layer = flags & 1;
  if (!get_varint(payload, pos, h.walk_steps) || !get_varint(payload, pos, h.insertions)) {
    return bad("refinement record header is cut short or malformed");
  }
  if (state.format >= 2) {
    if (!get_varint(payload, pos, h.min_shift))
      return bad("refinement record header is cut short or malformed");
    if (h.min_shift > kMaxShift)
      return bad("refinement record shift " + std::to_string(h.min_shift) + " too large");
  }
  const uint32_t vertices_before = state.mesh.vertex_count();
  // Each insertion needs at least one walk step's worth of bits; refuse
  // counts that could not fit before allocating for them.
  if (h.walk_steps > vertices_before) {
    return bad("refinement record walks " + std::to_string(h.walk_steps) +
               " vertices but the mesh has " + std::to_string(vertices_before));
  }
  if (h.insertions > 64 * static_cast<uint64_t>(payload.size())) {
    return bad("refinement record claims " + std::to_string(h.insertions) +
               " insertions, more than its size allows");
  }
  if (h.starts_layer) {
    state.layer += 1;
    state.cursor = state.order_head;
    state.last_count = 0;
  } else if (state.layer == 0) {
    return bad("first refinement record does not start a layer");
  }

  state.models.v_models = state.format >= 3;
  const std::span<const uint8_t> block = payload.subspan(pos);
  return state.models.v_models ? decode_structure_block<true>(state, block, h, expected_vertices,
                                                              expected_faces, applied)
                               : decode_structure_block<false>(state, block, h, expected_vertices,
                                                               expected_faces, applied);
}

}  // namespace meshstream
