// Edge points of one level (see edge_points.h). The classification is the
// one of rules::zorin_point; an edge with an extraordinary endpoint is left
// pending in the first pass and finished at its centre(s): one centre gives
// the point, two are averaged ((e_a + e_b) / 2 is the same bits in either
// arrival order, float addition being commutative). The stencil sum at a
// centre adds the same terms in the same order as rules::extraordinary_point
// (centre first, then the ring from the edge's other endpoint on), so every
// bit agrees with the per-edge evaluation (tests/asa/asa_edge_points_test.cpp).
// The SSE path multiplies and adds separately, like scalar code built for
// baseline x86-64 (no FMA to contract into); a build with FMA enabled could
// contract the per-edge reference differently.
#include "common/asa/edge_points.h"

#include "common/asa/butterfly_rules.h"

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

namespace meshstream::asa {
namespace {

// Prefetch distance of pass 1, in corners.
constexpr uint32_t kAhead = 64;

// Arrival states of a pending edge's new vertex.
enum : uint8_t { kOneCentre = 1, kTwoCentres = 2, kSecondOfTwo = 3 };

inline bool extraordinary(const LevelView& m, uint32_t v) {
  const uint32_t K = m.valence[v];
  return m.vertex_features[v] == 0 && K != 6 && K >= 3;
}

inline void note_centre(uint32_t v, uint32_t corner, EdgePointScratch& s) {
  if (s.vertex_corner[v] != kNone) return;
  s.vertex_corner[v] = corner;
  s.centres.push_back(v);
}

// Pass 2's prefetches while centre k is computed.
[[gnu::always_inline]] inline void prefetch_centre(const LevelView& m, const uint32_t* edge_vertex,
                                                   const EdgePointScratch& s,
                                                   const uint32_t* centres, uint32_t count,
                                                   uint32_t k, bool cached) {
  const uint32_t* opp = m.opposite;
  const uint32_t* cv = m.corner_vertex;
  if (cached) {
    // Fan corners are independent loads: fetch a later centre's corner
    // data, then a nearer one's ring positions.
    if (k + 8 < count) {
      for (uint32_t i = s.fan_start[k + 8]; i < s.fan_start[k + 9]; ++i) {
        const uint32_t y = s.fan_corner[i];
        __builtin_prefetch(cv + next_corner(y));
        __builtin_prefetch(edge_vertex + prev_corner(y));
      }
    }
    if (k + 4 < count) {
      __builtin_prefetch(m.positions + centres[k + 4]);
      for (uint32_t i = s.fan_start[k + 4]; i < s.fan_start[k + 5]; ++i)
        __builtin_prefetch(m.positions + cv[next_corner(s.fan_corner[i])]);
    }
  } else if (k + 4 < count) {
    // The start of a later centre's fan walk (the walk itself is a chain).
    const uint32_t u = centres[k + 4];
    const uint32_t y = s.vertex_corner[u];
    __builtin_prefetch(m.positions + u);
    __builtin_prefetch(opp + y);
    __builtin_prefetch(cv + y);
    __builtin_prefetch(m.valence + u);
  }
}

// The K stencil sums of one centre, sum j = centre + sum_i ring[i + j] * w_i,
// each adding its terms in the order of rules::extraordinary_point.
[[gnu::always_inline]] inline void sum_stencils(uint32_t K, const float* weights, Vec3f centre,
                                                const float* rx, const float* ry, const float* rz,
                                                float* sx, float* sy, float* sz) {
#if defined(__SSE2__)
  // Four sums at a time; each lane adds exactly the scalar terms in order
  // (a vector multiply/add rounds each lane like the scalar operation).
  for (uint32_t g = 0; g < K; g += 4) {
    __m128 ax = _mm_set1_ps(centre.x), ay = _mm_set1_ps(centre.y), az = _mm_set1_ps(centre.z);
    for (uint32_t i = 0; i < K; ++i) {
      const __m128 wi = _mm_set1_ps(weights[i]);
      ax = _mm_add_ps(ax, _mm_mul_ps(_mm_loadu_ps(rx + i + g), wi));
      ay = _mm_add_ps(ay, _mm_mul_ps(_mm_loadu_ps(ry + i + g), wi));
      az = _mm_add_ps(az, _mm_mul_ps(_mm_loadu_ps(rz + i + g), wi));
    }
    _mm_storeu_ps(sx + g, ax);
    _mm_storeu_ps(sy + g, ay);
    _mm_storeu_ps(sz + g, az);
  }
#else
  for (uint32_t j = 0; j < K; ++j) {
    sx[j] = centre.x;
    sy[j] = centre.y;
    sz[j] = centre.z;
  }
  for (uint32_t i = 0; i < K; ++i) {
    const float wi = weights[i];
    for (uint32_t j = 0; j < K; ++j) {
      sx[j] += rx[i + j] * wi;
      sy[j] += ry[i + j] * wi;
      sz[j] += rz[i + j] * wi;
    }
  }
#endif
}

// Each split edge of the centre gets its sum; an edge with two extraordinary
// centres gets the average of both (in either arrival order: same bits).
// With `bound` (Zorin placement: the point is final here), the offset bound
// is applied to the final point with the ring's own copy of the endpoints
// (rules::bound_offset gives the same bits: A + B and |B - A| do not depend
// on the order), so no scattered reads are needed for it.
[[gnu::always_inline]] inline void store_centre_points(
    const LevelView& m, uint32_t K, const uint32_t* ids, const uint32_t* edge_corners, Vec3f centre,
    const float* rx, const float* ry, const float* rz, const float* sx, const float* sy,
    const float* sz, bool bound, uint32_t first_new, Vec3f* pos, EdgePointScratch& s) {
  for (uint32_t j = 0; j < K; ++j) {
    const uint32_t id = ids[j];
    if (id == kNone) continue;
    const Vec3f sum{sx[j], sy[j], sz[j]};
    uint8_t& state = s.arrivals[id - first_new];
    Vec3f q;
    if (state == kTwoCentres) {
      pos[id] = sum;
      state = kSecondOfTwo;
      continue;  // final at the second centre
    } else if (state == kSecondOfTwo) {
      q = (pos[id] + sum) * 0.5f;
    } else {
      q = sum;
    }
    if (bound)
      q = rules::bound_offset_between(m, edge_corners[j], centre, {rx[j], ry[j], rz[j]}, q);
    pos[id] = q;
  }
}

// Pass 2: every centre's stencil for each of its split edges. The ring is
// gathered once into coordinate arrays, and the K sums are accumulated
// together, term by term: each sum still adds its terms in the order of
// rules::extraordinary_point (same bits), but the K independent sums
// vectorize.
[[gnu::noinline]] void centre_points(const LevelView& m, const uint32_t* edge_vertex,
                                     uint32_t first_new, const ButterflyWeights& wt,
                                     bool bound_here, Vec3f* pos, EdgePointScratch& s) {
  const uint32_t* opp = m.opposite;
  const uint32_t* cv = m.corner_vertex;
  // Fans either come from the cache (a uniform child level: no walking) or
  // are walked and recorded into it.
  const bool cached = s.fans_valid;
  const bool record = !cached && s.record_fans;
  if (record) {
    s.fan_vertex.clear();
    s.fan_corner.clear();
    s.fan_start.assign(1, 0);
  }
  const uint32_t* const centres = cached ? s.fan_vertex.data() : s.centres.data();
  const uint32_t count = static_cast<uint32_t>(cached ? s.fan_vertex.size() : s.centres.size());
  for (uint32_t k = 0; k < count; ++k) {
    const uint32_t v = centres[k];
    prefetch_centre(m, edge_vertex, s, centres, count, k, cached);
    const uint32_t K = m.valence[v];
    const float* weights = wt.extraordinary(K);
    uint32_t x = kNone;
    const uint32_t* fan = nullptr;
    if (cached) {
      fan = s.fan_corner.data() + s.fan_start[k];
    } else {
      x = s.vertex_corner[v];
      s.vertex_corner[v] = kNone;
    }
    const size_t need = 9 * static_cast<size_t>(K) + 24;
    if (s.ring.size() < need) {
      s.ring.assign(need, 0.0f);  // the padding stays zero
      s.ring_ids.resize(K);
      s.ring_corners.resize(K);
    }
    // Layout: ring x, y, z (2K + 4 each: the ring twice, so rotations are
    // contiguous, then zero padding for the last vector), then sums x, y, z
    // (K + 4 each).
    const uint32_t stride = 2 * K + 4;
    float* rx = s.ring.data();
    float* ry = rx + stride;
    float* rz = ry + stride;
    float* sx = rz + stride;
    float* sy = sx + K + 4;
    float* sz = sy + K + 4;
    uint32_t* ids = s.ring_ids.data();
    uint32_t* edge_corners = s.ring_corners.data();
    for (uint32_t j = 0; j < K; ++j) {
      if (cached) {
        x = fan[j];
      } else if (record) {
        s.fan_corner.push_back(x);
      }
      const uint32_t nx = next_corner(x);
      const Vec3f p = m.positions[cv[nx]];
      rx[j] = rx[j + K] = p.x;
      ry[j] = ry[j + K] = p.y;
      rz[j] = rz[j + K] = p.z;
      ids[j] = edge_vertex[prev_corner(x)];
      edge_corners[j] = prev_corner(x);
      if (!cached) x = next_corner(opp[nx]);
    }
    if (record) {
      s.fan_vertex.push_back(v);
      s.fan_start.push_back(static_cast<uint32_t>(s.fan_corner.size()));
    }
    for (uint32_t j = 2 * K; j < stride; ++j) rx[j] = ry[j] = rz[j] = 0.0f;
    const Vec3f centre = m.positions[v] * weights[K];
    sum_stencils(K, weights, centre, rx, ry, rz, sx, sy, sz);
    store_centre_points(m, K, ids, edge_corners, m.positions[v], rx, ry, rz, sx, sy, sz, bound_here,
                        first_new, pos, s);
  }
}

// Pass 1 for one edge named by corner c with new vertex id: curve and
// regular stencils are written; an edge at an extraordinary vertex is noted
// for its centre(s).
[[gnu::always_inline]] inline void first_pass_edge(const LevelView& m, uint32_t c, uint32_t id,
                                                   bool irregular_a, bool irregular_b,
                                                   const uint32_t* across, float w, bool project,
                                                   bool bound, uint32_t first_new, Vec3f* pos,
                                                   EdgePointScratch& s) {
  const uint32_t* cv = m.corner_vertex;
  const uint8_t* fe = m.feature_edge;
  if (fe[c]) {
    const Vec3f q = rules::curve_point(m, c);
    pos[id] = bound ? rules::bound_offset(m, c, q) : q;
    return;
  }
  const uint32_t o = m.opposite[c];
  const uint32_t n = next_corner(c), p = prev_corner(c);
  if (!irregular_a && !irregular_b) {
    Vec3f q;
    if (w == 0.0f && across) {
      // rules::regular_point with w = 0, reading the wing vertices from
      // `across` (one line of the neighbour instead of four lookups).
      const uint32_t no = next_corner(o), po = prev_corner(o);
      const Vec3f A = m.positions[cv[n]], B = m.positions[cv[p]];
      const Vec3f b0 = m.positions[cv[c]], b1 = m.positions[across[c]];
      const Vec3f wA0 = fe[p] ? A + b0 - B : m.positions[across[p]];
      const Vec3f wB0 = fe[n] ? B + b0 - A : m.positions[across[n]];
      const Vec3f wA1 = fe[no] ? A + b1 - B : m.positions[across[no]];
      const Vec3f wB1 = fe[po] ? B + b1 - A : m.positions[across[po]];
      const Vec3f wings = (wA0 + wB1) + (wB0 + wA1);
      q = (A + B) * 0.5f + (b0 + b1) * 0.125f - wings * 0.0625f;
    } else {
      q = rules::regular_point(m, c, w);
    }
    if (project) q = rules::project_point(m, c, q);
    pos[id] = bound ? rules::bound_offset(m, c, q) : q;
    return;
  }
  s.arrivals[id - first_new] = irregular_a && irregular_b ? kTwoCentres : kOneCentre;
  if (!s.fans_valid) {
    if (irregular_a) note_centre(cv[n], n, s);
    if (irregular_b) note_centre(cv[p], next_corner(o), s);
  }
  if (project) s.pending.push_back(c);
}

}  // namespace

void compute_edge_points(const LevelView& m, const uint32_t* edge_vertex, uint32_t first_new,
                         uint32_t new_count, const ButterflyWeights& wt, EdgePlacement placement,
                         Vec3f* pos, EdgePointScratch& s, const std::vector<uint32_t>* naming) {
  const uint32_t corners = 3 * m.face_count;
  const uint32_t* opp = m.opposite;
  const uint32_t* cv = m.corner_vertex;
  const bool project = placement == EdgePlacement::kProjection;
  const bool bound = wt.bounds_offsets();
  const float w = wt.tension();
  if (s.vertex_corner.size() < m.vertex_count) s.vertex_corner.resize(m.vertex_count, kNone);
  s.arrivals.resize(new_count);
  s.centres.clear();
  s.pending.clear();
  const uint32_t* across = m.across;
  const Vec3f* P = m.positions;

  if (naming) {
    s.fans_valid = false;  // the cache is for uniform levels only
    s.record_fans = false;
    // Adaptive levels: visit only the split edges, each with its own
    // stencil (an extraordinary vertex usually has only some of its edges
    // split, so evaluating all K of its stencils at once would be wasted).
    for (const uint32_t c : *naming) pos[edge_vertex[c]] = rules::edge_point(m, c, wt, placement);
    return;
  } else {
    if (!across) {  // a level built by hand (tests): derive it
      fill_across(cv, opp, corners, s.across);
      across = s.across.data();
    }
    // Per vertex: is it an extraordinary centre (one byte, read twice per edge).
    s.irregular.resize(m.vertex_count);
    uint8_t* irregular = s.irregular.data();
    for (uint32_t v = 0; v < m.vertex_count; ++v) irregular[v] = extraordinary(m, v);
    // The stencil reads are scattered over the mesh; prefetching what
    // corners a few faces ahead will read keeps several misses in flight (on
    // a mesh in scan order most of them miss the cache).
    for (uint32_t c = 0; c < corners; ++c) {
      if (c + kAhead < corners) {
        const uint32_t ahead = c + kAhead, half = c + kAhead / 2;
        __builtin_prefetch(P + cv[ahead]);
        const uint32_t o_ahead = opp[ahead];
        if (o_ahead != kNone) {
          __builtin_prefetch(across + o_ahead);
          __builtin_prefetch(P + across[ahead]);
        }
        const uint32_t o_half = opp[half];
        if (o_half != kNone) {
          const uint32_t wing = across[prev_corner(o_half)];
          if (wing != kNone) __builtin_prefetch(P + wing);
          __builtin_prefetch(irregular + across[half]);
        }
      }
      const uint32_t id = edge_vertex[c];
      const uint32_t o = opp[c];
      if (id == kNone || (o != kNone && o < c)) continue;
      first_pass_edge(m, c, id, irregular[cv[next_corner(c)]], irregular[cv[prev_corner(c)]],
                      across, w, project, bound, first_new, pos, s);
    }
  }

  // Zorin placement: the centres apply the bound themselves; with
  // projection it comes after the projection, below.
  centre_points(m, edge_vertex, first_new, wt, bound && !project, pos, s);

  // Projection placement (and then the offset bound) of the extraordinary
  // edges, now that their points are known.
  for (const uint32_t c : s.pending) {
    const uint32_t id = edge_vertex[c];
    const Vec3f q = rules::project_point(m, c, pos[id]);
    pos[id] = bound ? rules::bound_offset(m, c, q) : q;
  }
}

void map_fans_to_uniform_children(EdgePointScratch& s) {
  for (uint32_t& c : s.fan_corner) c = 4 * c - c % 3;
  s.fans_valid = true;
}

}  // namespace meshstream::asa
