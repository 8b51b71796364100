// Corners grouped by vertex: corner k at v contributes the outgoing
// half-edge v -> to(k) = vertex(next k) and the incoming third(k) -> v, with
// third(k) = vertex(prev k). The twin of v -> w is the incoming half-edge of
// the corner at v whose third vertex is w, so matching, validation and the
// one-fan check all happen inside one vertex's contiguous bucket.
//
// Speed (this runs on every call the client makes): the buckets are kept as
// three parallel arrays so that the thirds of one bucket are contiguous and
// one comparison against all of them is a handful of 4-wide SIMD compares
// giving a bit mask (no data-dependent branch per candidate); buckets of up
// to 64 corners (every vertex of ordinary meshes) keep their per-entry state
// in registers and small stack arrays. Larger fans are sorted by third and
// matched by binary search.
#include "common/asa/corner_table.h"

#include <algorithm>
#include <bit>
#include <numeric>
#include <string>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "common/asa/level_mesh.h"

namespace meshstream::asa {
namespace {

constexpr uint32_t kSmallFan = 64;  // buckets matched with bit masks
constexpr uint32_t kPad = 4;        // readable entries past the last bucket

std::string edge_name(uint32_t a, uint32_t b) {
  return "edge (" + std::to_string(a) + ", " + std::to_string(b) + ")";
}

Status same_direction_error(uint32_t v, uint32_t to, uint32_t face_a, const std::string& face_b) {
  return make_error(
      ErrorCode::kNonManifold,
      edge_name(v, to) +
          " is used twice in the same direction (more than two faces, or inconsistent "
          "orientation) by faces " +
          std::to_string(face_a) + " and " + face_b);
}

// Bit j set when third[j] == x, for j < n <= 64 (entries up to the next
// multiple of 4 must be readable; bits at and past n are cleared).
inline uint64_t match_mask(const uint32_t* third, uint32_t n, uint32_t x) {
  uint64_t mask = 0;
#if defined(__SSE2__)
  const __m128i key = _mm_set1_epi32(static_cast<int>(x));
  for (uint32_t j = 0; j < n; j += 4) {
    const __m128i h = _mm_loadu_si128(reinterpret_cast<const __m128i*>(third + j));
    const uint32_t bits =
        static_cast<uint32_t>(_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(h, key))));
    mask |= static_cast<uint64_t>(bits) << j;
  }
#else
  for (uint32_t j = 0; j < n; ++j) mask |= static_cast<uint64_t>(third[j] == x) << j;
#endif
  return n == 64 ? mask : mask & ((uint64_t{1} << n) - 1);
}

// Error for a bucket whose entries do not form one fan: a duplicate outgoing
// edge when there is one (as Adjacency reports it), else a non-manifold vertex.
Status fan_error(uint32_t v, const uint32_t* to, const uint32_t* corner, uint32_t n) {
  for (uint32_t i = 0; i < n; ++i)
    for (uint32_t j = i + 1; j < n; ++j)
      if (to[i] == to[j])
        return same_direction_error(v, to[i], corner[i] / 3, std::to_string(corner[j] / 3));
  return make_error(
      ErrorCode::kNonManifold,
      "vertex " + std::to_string(v) + " joins more than one fan of faces (non-manifold vertex)");
}

// Outcome of matching one small bucket (errors are built off the hot path).
enum MatchCode : uint32_t { kMatched = 0, kTooManyFaces = 1, kSameDirection = 2, kNotOneFan = 3 };

// One bucket of at most kSmallFan entries. With Packed (n < 16) the
// successor of each entry lives in a 4-bit field of one register, so the
// fan walk below is register-only. On error, *bad is the entry at fault.
// Groups > 0: n <= 4 * Groups, the thirds are held in registers.
template <bool Packed, uint32_t Groups>
inline uint32_t match_small(const uint32_t* to, const uint32_t* third, const uint32_t* corner,
                            uint32_t n, uint32_t* opposite, uint32_t* across, uint32_t* bad) {
  constexpr uint32_t kEnd = Packed ? 15 : kSmallFan;
  uint8_t succ[Packed ? 1 : kSmallFan];
  uint64_t packed = ~uint64_t{0};
  uint64_t has_pred = 0;
  const uint64_t all = n == 64 ? ~uint64_t{0} : (uint64_t{1} << n) - 1;
#if defined(__SSE2__)
  __m128i held[Groups > 0 ? Groups : 1];
  if constexpr (Groups > 0) {
    for (uint32_t g = 0; g < Groups; ++g)
      held[g] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(third + 4 * g));
  }
#endif
  for (uint32_t i = 0; i < n; ++i) {
    uint64_t mask;
#if defined(__SSE2__)
    if constexpr (Groups > 0) {
      const __m128i key = _mm_set1_epi32(static_cast<int>(to[i]));
      uint32_t bits = 0;
      for (uint32_t g = 0; g < Groups; ++g) {
        bits |=
            static_cast<uint32_t>(_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(held[g], key))))
            << (4 * g);
      }
      mask = bits & all;
    } else {
      mask = match_mask(third, n, to[i]);
    }
#else
    mask = match_mask(third, n, to[i]);
#endif
    const uint32_t pc = prev_corner(corner[i]);
    if (mask == 0) {
      opposite[pc] = kNone;
      across[pc] = kNone;
      if constexpr (!Packed) succ[i] = kEnd;
      continue;
    }
    *bad = i;
    if (mask & (mask - 1)) return kTooManyFaces;
    // Two outgoing half-edges v -> to: the same edge twice in one direction.
    if (has_pred & mask) return kSameDirection;
    const uint32_t j = static_cast<uint32_t>(std::countr_zero(mask));
    has_pred |= mask;
    if constexpr (Packed) {
      packed &= ~(uint64_t{15} << (4 * i)) | (uint64_t{j} << (4 * i));
    } else {
      succ[i] = static_cast<uint8_t>(j);
    }
    opposite[pc] = next_corner(corner[j]);
    across[pc] = to[j];
  }
  // One fan: at most one entry without predecessor (an open fan's first
  // face); walking successors from it, or from any entry of a closed fan,
  // must visit all n.
  const uint64_t starts = all & ~has_pred;
  if (starts & (starts - 1)) return kNotOneFan;
  const uint32_t start = starts ? static_cast<uint32_t>(std::countr_zero(starts)) : 0;
  uint32_t visited = 0, i = start;
  do {
    ++visited;
    if constexpr (Packed) {
      i = static_cast<uint32_t>(packed >> (4 * i)) & 15;
    } else {
      i = succ[i];
    }
  } while (i != kEnd && i != start && visited <= n);
  return visited == n ? kMatched : kNotOneFan;
}

// The error for a failed small bucket (cold).
[[gnu::noinline, gnu::cold]] Status small_bucket_error(uint32_t code, uint32_t v,
                                                       const uint32_t* to, const uint32_t* corner,
                                                       uint32_t n, uint32_t bad) {
  if (code == kTooManyFaces) {
    return make_error(ErrorCode::kNonManifold, edge_name(v, to[bad]) + " has more than two faces");
  }
  if (code == kSameDirection)
    return same_direction_error(v, to[bad], corner[bad] / 3, "another face");
  return fan_error(v, to, corner, n);
}

// One bucket of more than kSmallFan entries: sorted by third (the three
// arrays permuted together), matched by binary search.
Status match_large(uint32_t v, uint32_t* to, uint32_t* third, uint32_t* corner, uint32_t n,
                   uint32_t* opposite, uint32_t* across, CornerTableScratch& s) {
  std::vector<uint32_t>& order = s.order;
  order.resize(n);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(),
            [&](uint32_t a, uint32_t b) { return third[a] < third[b]; });
  std::vector<uint32_t>& tmp = s.permuted;
  tmp.resize(3 * static_cast<size_t>(n));
  for (uint32_t k = 0; k < n; ++k) {
    tmp[k] = to[order[k]];
    tmp[n + k] = third[order[k]];
    tmp[2 * n + k] = corner[order[k]];
  }
  std::copy(tmp.begin(), tmp.begin() + n, to);
  std::copy(tmp.begin() + n, tmp.begin() + 2 * n, third);
  std::copy(tmp.begin() + 2 * n, tmp.end(), corner);

  std::vector<uint32_t>& match = s.order;  // reused: per entry, its successor around v
  match.assign(n, kNone);
  std::vector<uint8_t>& has_pred = s.visited;
  has_pred.assign(n, 0);
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t x = to[i];
    const uint32_t* lo = std::lower_bound(third, third + n, x);
    const uint32_t pc = prev_corner(corner[i]);
    if (lo == third + n || *lo != x) {
      opposite[pc] = kNone;
      across[pc] = kNone;
      continue;
    }
    if (lo + 1 != third + n && lo[1] == x) {
      return make_error(ErrorCode::kNonManifold, edge_name(v, x) + " has more than two faces");
    }
    const uint32_t found = static_cast<uint32_t>(lo - third);
    if (has_pred[found]) return same_direction_error(v, x, corner[i] / 3, "another face");
    has_pred[found] = 1;
    match[i] = found;
    opposite[pc] = next_corner(corner[found]);
    across[pc] = to[found];
  }
  uint32_t start = kNone, starts = 0;
  for (uint32_t i = 0; i < n; ++i)
    if (!has_pred[i]) {
      ++starts;
      start = i;
    }
  if (starts == 0) start = 0;
  uint32_t visited = 0;
  if (starts <= 1) {
    uint32_t i = start;
    do {
      ++visited;
      i = match[i];
    } while (i != kNone && i != start && visited <= n);
  }
  if (starts > 1 || visited != n) return fan_error(v, to, corner, n);
  return {};
}

}  // namespace

Status build_opposites(const Mesh& mesh, std::vector<uint32_t>& opposite, CornerTableScratch& s) {
  std::vector<uint32_t> across;
  return build_opposites(mesh, opposite, across, s);
}

Status build_opposites(const Mesh& mesh, std::vector<uint32_t>& opposite,
                       std::vector<uint32_t>& across_out, CornerTableScratch& s) {
  const uint32_t V = mesh.vertex_count(), corners = 3 * mesh.face_count();
  const uint32_t* cv = corners ? mesh.triangles.front().data() : nullptr;
  s.offset.assign(static_cast<size_t>(V) + 1, 0);
  for (uint32_t c = 0; c < corners; ++c) ++s.offset[cv[c] + 1];
  for (uint32_t v = 0; v < V; ++v) s.offset[v + 1] += s.offset[v];
  s.to.resize(static_cast<size_t>(corners) + kPad);
  s.third.resize(static_cast<size_t>(corners) + kPad);
  s.corner.resize(static_cast<size_t>(corners) + kPad);
  uint32_t* to = s.to.data();
  uint32_t* third = s.third.data();
  uint32_t* corner = s.corner.data();
  s.cursor.assign(s.offset.begin(), s.offset.end() - 1);
  uint32_t* cursor = s.cursor.data();
  for (uint32_t f = 0; f < corners; f += 3) {
    const uint32_t a = cv[f], b = cv[f + 1], c = cv[f + 2];
    const uint32_t ka = cursor[a]++;
    to[ka] = b, third[ka] = c, corner[ka] = f;
    const uint32_t kb = cursor[b]++;
    to[kb] = c, third[kb] = a, corner[kb] = f + 1;
    const uint32_t kc = cursor[c]++;
    to[kc] = a, third[kc] = b, corner[kc] = f + 2;
  }
  opposite.resize(corners);  // every entry is written below
  across_out.resize(corners);
  uint32_t* opp = opposite.data();
  uint32_t* across = across_out.data();
  const uint32_t* offset = s.offset.data();
  for (uint32_t v = 0; v < V; ++v) {
    const uint32_t begin = offset[v], n = offset[v + 1] - begin;
    if (n == 0) continue;
    if (n <= kSmallFan) {
      uint32_t bad = 0;
      const uint32_t *t = to + begin, *h = third + begin, *k = corner + begin;
      uint32_t code;
      if (n <= 4)
        code = match_small<true, 1>(t, h, k, n, opp, across, &bad);
      else if (n <= 8)
        code = match_small<true, 2>(t, h, k, n, opp, across, &bad);
      else if (n <= 12)
        code = match_small<true, 3>(t, h, k, n, opp, across, &bad);
      else if (n < 16)
        code = match_small<true, 4>(t, h, k, n, opp, across, &bad);
      else
        code = match_small<false, 0>(t, h, k, n, opp, across, &bad);
      if (code != kMatched) return small_bucket_error(code, v, to + begin, corner + begin, n, bad);
    } else {
      Status ok = match_large(v, to + begin, third + begin, corner + begin, n, opp, across, s);
      if (!ok) return ok;
    }
  }
  return {};
}

void faces_per_vertex(const CornerTableScratch& s, std::vector<uint32_t>& faces) {
  const size_t V = s.offset.empty() ? 0 : s.offset.size() - 1;
  faces.resize(V);
  for (size_t v = 0; v < V; ++v) faces[v] = s.offset[v + 1] - s.offset[v];
}

}  // namespace meshstream::asa

// ---- LiveCornerTable ------------------------------------------------------

namespace meshstream::asa {

Status LiveCornerTable::rebuild(const Mesh& mesh) {
  const uint32_t V = mesh.vertex_count(), F = mesh.face_count();
  if (auto built = build_opposites(mesh, opposite_, scratch_); !built) {
    opposite_.clear();
    vertex_faces_.clear();
    return built;
  }
  vertex_faces_.resize(V);
  for (uint32_t v = 0; v < V; ++v) {
    vertex_faces_[v].clear();
    vertex_faces_[v].reserve(scratch_.offset[v + 1] - scratch_.offset[v]);
  }
  for (uint32_t f = 0; f < F; ++f)
    for (uint32_t v : mesh.triangles[f]) vertex_faces_[v].push_back(f);
  face_stamp_.assign(F, 0);
  vertex_stamp_.assign(V, 0);
  generation_ = 0;
  return {};
}

// Finds the corner across the edge that corner c faces (u -> w in c's face)
// among the faces around u and links both ways; kNone on a boundary.
Status LiveCornerTable::link_corner(const Mesh& mesh, uint32_t c) {
  const uint32_t g = c / 3;
  const Triangle& tg = mesh.triangles[g];
  const uint32_t u = tg[(c + 1) % 3], w = tg[(c + 2) % 3];
  const std::vector<uint32_t>& around =
      vertex_faces_[u].size() <= vertex_faces_[w].size() ? vertex_faces_[u] : vertex_faces_[w];
  uint32_t partner = kNone, found = 0;
  for (uint32_t h : around) {
    if (h == g) continue;
    const Triangle& t = mesh.triangles[h];
    const int j = t[0] == u ? 0 : t[1] == u ? 1 : t[2] == u ? 2 : -1;
    if (j < 0) continue;
    if (t[(j + 2) % 3] == w) {  // w -> u: the twin
      partner = 3 * h + static_cast<uint32_t>((j + 1) % 3);
      ++found;
    } else if (t[(j + 1) % 3] == w) {
      return same_direction_error(u, w, g, "face " + std::to_string(h));
    }
  }
  if (found > 1)
    return make_error(ErrorCode::kNonManifold, edge_name(u, w) + " has more than two faces");
  opposite_[c] = partner;
  if (partner != kNone) opposite_[partner] = c;
  return {};
}

// The faces around v form one fan: walking across v's edges from one face
// (both ways where a boundary stops the walk) reaches all of them.
Status LiveCornerTable::check_fan(const Mesh& mesh, uint32_t v) const {
  const std::vector<uint32_t>& around = vertex_faces_[v];
  if (around.size() <= 1) return {};
  const size_t n = around.size();
  const size_t reached = faces_reached_around(mesh, opposite_.data(), v, around.front(), n,
                                              [](uint32_t) { return true; });
  if (reached != n) {
    return make_error(ErrorCode::kNonManifold, "vertex " + std::to_string(v) +
                                                   " joins more than one fan of faces "
                                                   "(non-manifold vertex)");
  }
  return {};
}

Status LiveCornerTable::apply(const Mesh& mesh, const std::vector<uint32_t>& changed,
                              const std::vector<Triangle>& old_corners) {
  const uint32_t V = mesh.vertex_count(), F = mesh.face_count(), Fo = face_count();
  if (F < Fo || V < vertex_count()) return rebuild(mesh);
  vertex_faces_.resize(V);
  opposite_.resize(3 * static_cast<size_t>(F), kNone);
  face_stamp_.resize(F, 0);
  vertex_stamp_.resize(V, 0);
  if (++generation_ == 0) {  // wrapped: clear the stamps once
    std::fill(face_stamp_.begin(), face_stamp_.end(), 0);
    std::fill(vertex_stamp_.begin(), vertex_stamp_.end(), 0);
    generation_ = 1;
  }
  const uint32_t gen = generation_;
  relink_.clear();
  fan_vertices_.clear();
  auto relink = [&](uint32_t f) {
    if (face_stamp_[f] == gen) return;
    face_stamp_[f] = gen;
    relink_.push_back(f);
  };
  auto fan_vertex = [&](uint32_t v) {
    if (vertex_stamp_[v] == gen) return;
    vertex_stamp_[v] = gen;
    fan_vertices_.push_back(v);
  };
  // Take the changed faces out of their old vertices' lists; their old
  // neighbours lose them as partners (a neighbour that shares an edge with
  // a changed face afterwards is linked again from the changed side).
  for (size_t i = 0; i < changed.size(); ++i) {
    const uint32_t f = changed[i];
    if (f >= F || face_stamp_[f] == gen) continue;
    relink(f);
    if (f >= Fo) continue;
    const Triangle& old = old_corners[i];
    for (int k = 0; k < 3; ++k) {
      const uint32_t o = opposite_[3 * f + k];
      if (o != kNone) opposite_[o] = kNone;
      opposite_[3 * f + k] = kNone;
      std::vector<uint32_t>& list = vertex_faces_[old[k]];
      auto it = std::find(list.begin(), list.end(), f);
      if (it != list.end()) {
        *it = list.back();
        list.pop_back();
      }
      fan_vertex(old[k]);
    }
  }
  const size_t changed_end = relink_.size();
  for (size_t i = 0; i < changed_end; ++i) {
    const uint32_t f = relink_[i];
    for (uint32_t v : mesh.triangles[f]) {
      if (v >= V)
        return make_error(ErrorCode::kInvalidMesh, "triangle " + std::to_string(f) +
                                                       " refers to vertex " + std::to_string(v) +
                                                       " but there are only " + std::to_string(V));
      vertex_faces_[v].push_back(f);
      fan_vertex(v);
    }
  }
  // Only the changed faces' corners are searched; an old neighbour that
  // finds no new partner stays a boundary (its entry was cleared above).
  for (size_t i = 0; i < changed_end; ++i) {
    const uint32_t f = relink_[i];
    for (uint32_t c = 3 * f; c < 3 * f + 3; ++c)
      if (auto ok = link_corner(mesh, c); !ok) return ok;
  }
  for (uint32_t v : fan_vertices_)
    if (auto ok = check_fan(mesh, v); !ok) return ok;
  return {};
}

}  // namespace meshstream::asa
