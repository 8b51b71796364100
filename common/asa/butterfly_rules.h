// The modified Butterfly rules as inline functions, so the split loops
// (split_uniform.cpp, split_adaptive.cpp) inline them; butterfly_stencils.cpp
// documents the method and every deviation. Internal to common/asa.
#pragma once

#include <algorithm>
#include <cmath>

#include "common/asa/butterfly_stencils.h"

namespace meshstream::asa::rules {

inline Vec3f P(const LevelView& m, uint32_t v) { return m.positions[v]; }

// Walks around vertex(x) counter-clockwise from corner x until an edge is a
// feature edge; returns the far end of that edge, or kNone after `limit` steps.
inline uint32_t walk_to_feature_ccw(const LevelView& m, uint32_t x, uint32_t limit) {
  for (uint32_t step = 0; step < limit; ++step) {
    const uint32_t e = next_corner(x);  // faces edge (vertex(prev x), vertex(x))
    if (m.feature_edge[e]) return m.corner_vertex[prev_corner(x)];
    x = next_corner(m.opposite[e]);
  }
  return kNone;
}

// Same, clockwise.
inline uint32_t walk_to_feature_cw(const LevelView& m, uint32_t x, uint32_t limit) {
  for (uint32_t step = 0; step < limit; ++step) {
    const uint32_t e = prev_corner(x);  // faces edge (vertex(x), vertex(next x))
    if (m.feature_edge[e]) return m.corner_vertex[next_corner(x)];
    x = prev_corner(m.opposite[e]);
  }
  return kNone;
}

// Walk limit: a manifold vertex has at most as many faces as the mesh, but a
// bad table must not loop forever.
inline uint32_t walk_limit(const LevelView& m) { return m.face_count + 1; }

[[gnu::noinline]] inline Vec3f curve_point(const LevelView& m, uint32_t c) {
  const uint32_t n = next_corner(c), p = prev_corner(c);
  const uint32_t a = m.corner_vertex[n], b = m.corner_vertex[p];
  const Vec3f A = P(m, a), B = P(m, b);
  uint32_t xa = m.vertex_features[a] == 2 ? walk_to_feature_ccw(m, n, walk_limit(m)) : kNone;
  uint32_t xb = m.vertex_features[b] == 2 ? walk_to_feature_cw(m, p, walk_limit(m)) : kNone;
  const Vec3f XA = xa != kNone ? P(m, xa) : A + A - B;  // corner: extend by reflection
  const Vec3f XB = xb != kNone ? P(m, xb) : B + B - A;
  return (A + B) * (9.0f / 16.0f) - (XA + XB) * (1.0f / 16.0f);
}

// The third neighbour of regular interior vertex(x) counting from
// vertex(next(x)) counter-clockwise: straight across from it.
inline uint32_t across_neighbor(const LevelView& m, uint32_t x) {
  for (int i = 0; i < 3; ++i) x = next_corner(m.opposite[next_corner(x)]);
  return m.corner_vertex[next_corner(x)];
}

[[gnu::always_inline]] inline Vec3f regular_point(const LevelView& m, uint32_t c, float w) {
  const uint32_t n = next_corner(c), p = prev_corner(c);
  const uint32_t o = m.opposite[c];
  const uint32_t no = next_corner(o), po = prev_corner(o);
  const uint32_t a = m.corner_vertex[n], b = m.corner_vertex[p];
  const Vec3f A = P(m, a), B = P(m, b);
  const Vec3f b0 = P(m, m.corner_vertex[c]), b1 = P(m, m.corner_vertex[o]);
  // Wings: the vertex across each outer edge of the two triangles, reflected
  // when that edge is a boundary or crease.
  const Vec3f wA0 = m.feature_edge[p] ? A + b0 - B : P(m, m.corner_vertex[m.opposite[p]]);
  const Vec3f wB0 = m.feature_edge[n] ? B + b0 - A : P(m, m.corner_vertex[m.opposite[n]]);
  const Vec3f wA1 = m.feature_edge[no] ? A + b1 - B : P(m, m.corner_vertex[m.opposite[no]]);
  const Vec3f wB1 = m.feature_edge[po] ? B + b1 - A : P(m, m.corner_vertex[m.opposite[po]]);
  // Pairs chosen so that starting from the other side gives the same bits.
  const Vec3f wings = (wA0 + wB1) + (wB0 + wA1);
  if (w == 0.0f) {
    return (A + B) * 0.5f + (b0 + b1) * 0.125f - wings * 0.0625f;
  }
  const bool regular_a = m.vertex_features[a] == 0 && m.valence[a] == 6;
  const bool regular_b = m.vertex_features[b] == 0 && m.valence[b] == 6;
  const Vec3f DA = regular_a ? P(m, across_neighbor(m, n)) : A + A - B;
  const Vec3f DB = regular_b ? P(m, across_neighbor(m, no)) : B + B - A;
  return (A + B) * (0.5f - w) + (b0 + b1) * (0.125f + 2.0f * w) - wings * (0.0625f + w) +
         (DA + DB) * w;
}

// Extraordinary stencil of interior vertex(x), valence K, walking
// counter-clockwise from vertex(next(x)) (the edge's other endpoint, j = 0).
[[gnu::noinline]] inline Vec3f extraordinary_point(const LevelView& m, uint32_t x, uint32_t K,
                                                   const ButterflyWeights& wt) {
  const float* s = wt.extraordinary(K);
  Vec3f sum = P(m, m.corner_vertex[x]) * s[K];
  for (uint32_t j = 0; j < K; ++j) {
    sum += P(m, m.corner_vertex[next_corner(x)]) * s[j];
    x = next_corner(m.opposite[next_corner(x)]);
  }
  return sum;
}

[[gnu::always_inline]] inline Vec3f zorin_point(const LevelView& m, uint32_t c,
                                                const ButterflyWeights& wt) {
  if (m.feature_edge[c]) return curve_point(m, c);
  const uint32_t n = next_corner(c);
  const uint32_t o = m.opposite[c];
  const uint32_t no = next_corner(o);
  const uint32_t a = m.corner_vertex[n], b = m.corner_vertex[no];
  const bool feature_a = m.vertex_features[a] != 0, feature_b = m.vertex_features[b] != 0;
  // Valence below 3 (a two-face pillow) has no extraordinary rule: regular.
  const bool irregular_a = !feature_a && m.valence[a] != 6 && m.valence[a] >= 3;
  const bool irregular_b = !feature_b && m.valence[b] != 6 && m.valence[b] >= 3;
  if (!irregular_a && !irregular_b) return regular_point(m, c, wt.tension());
  if (irregular_a && irregular_b) {
    return (extraordinary_point(m, n, m.valence[a], wt) +
            extraordinary_point(m, no, m.valence[b], wt)) *
           0.5f;
  }
  return irregular_a ? extraordinary_point(m, n, m.valence[a], wt)
                     : extraordinary_point(m, no, m.valence[b], wt);
}

inline Vec3f unit_face_normal(const LevelView& m, uint32_t f) {
  const Vec3f p0 = P(m, m.corner_vertex[3 * f]);
  const Vec3f p1 = P(m, m.corner_vertex[3 * f + 1]);
  const Vec3f p2 = P(m, m.corner_vertex[3 * f + 2]);
  return normalized(cross(p1 - p0, p2 - p0));
}

// Projection placement of an interior edge's Butterfly point s (the thesis):
// only its offset along the averaged normal of the edge's two faces is kept.
inline Vec3f project_point(const LevelView& m, uint32_t c, Vec3f s) {
  const uint32_t o = m.opposite[c];
  const Vec3f mid =
      (P(m, m.corner_vertex[next_corner(c)]) + P(m, m.corner_vertex[prev_corner(c)])) * 0.5f;
  const Vec3f normal = normalized(unit_face_normal(m, c / 3) + unit_face_normal(m, o / 3));
  return mid + normal * dot(normal, s - mid);
}

// ---- No spikes: the bound on a new vertex's offset (issue 20, point 3) ----
//
// Let A, B be the edge's endpoints, M = (A + B) / 2 its midpoint, L = |B - A|
// and s the rule's point. Accepted offsets:
//
//   |s - M| <= L * (1/8 + min(1, sigma)),
//   sigma = max over the stencil's dihedral pairs (f, g) of
//           sin(theta_fg / 2) * max(1, L / (sqrt(3) * |centroid_f - centroid_g|))
//
// where theta_fg is the angle between the unit normals of faces f and g
// (sin(theta / 2) = |n_f - n_g| / 2), over the pairs the stencil sees: the
// edge's two faces with each other and each with its two wing faces (the
// faces across its other edges; a feature edge has no wing, its reflected
// wing lies in the face's plane). For a curve-rule (boundary, crease) edge,
// sigma is sin(phi / 2) of the curve's turning phi at A and at B. An
// irregular stencil (below) is allowed L / 8 only. Never more than 9/8 L.
//
// Why a smooth surface does not reach it: on a smooth surface the Butterfly
// point is the surface point over M up to higher-order terms (the rules
// reproduce planes exactly: on a plane the offset is 0), so |s - M| is about
// the sagitta of the surface's arc over the edge, L^2 k / 8 for the normal
// curvature k along AB. A dihedral angle samples the curvature over the
// distance d between the two faces' centroids: theta ~ k d, so the sagitta
// is ~ L^2 theta / (8 d) = L * sin(theta / 2) * L / (4 d) (small theta),
// which is L sigma times sqrt(3) / 4 = 0.43: under half the allowance (d is
// L / sqrt(3) for equilateral faces, where the factor L / (sqrt(3) d) is 1;
// it keeps the allowance for faces thin across the edge, whose centroids
// are close; faces long across it only get the equilateral allowance, which
// is more than their sagitta needs).
// L / 8 alone is the sagitta of an arc that turns 56 degrees between A and
// B, which a sampling fine enough to be called smooth does not do (a curve
// turning by phi per vertex gives L tan(phi / 4) / 2 ~ L phi / 8, inside
// L (1/8 + sin(phi / 2))). A shard breaks the relation between the offset
// and the edge's own length: a sliver wing (wing distance >> L), a fan of
// extreme valence or a stray vertex pulls s by a fraction (1/16 to 1/2) of a
// distance that has nothing to do with L, and the bound caps it at the
// edge's scale. Too far, s is pulled back to the bound along s - M
// (continuous: no pop as a vertex crosses it).
//
// The gentler rule, where the stencil is irregular and its angles are no
// evidence of curvature: an endpoint on a boundary or crease (the wings
// there are reflections), an endpoint of extreme valence (fewer than 4 or
// more than 12 faces: the K-rules' weights get large and alternating), a
// near-degenerate triangle among the edge's faces and wings (twice its area
// below 1/16 of its longest edge squared: an angle below about 3.6 degrees;
// its normal is noise). There the offset is capped at L / 8. The importer
// does not mark the spots it repaired (ImportReport only counts them, and a
// decoded stream carries nothing), so they are found by these geometric
// tests: a split non-manifold vertex or a detached face leaves a boundary,
// a collapsed spot leaves slivers and zero-length edges (L = 0: the midpoint).
//
// Every quantity is a function of the edge's stencil computed the same way
// from either side (|B - A| = |A - B|, A + B = B + A, each face's normal and
// centroid from its own corners, a maximum over a symmetric set of pairs),
// so both faces of the edge, region runs and full runs get the same bits.
// Cost: one comparison per edge; the rest only for offsets above L / 8.

constexpr float kFreeOffset = 0.125f;        // |s - M| <= L / 8 is always accepted
constexpr float kSliverQuality = 1.0f / 16;  // 2 area / longest^2 below: near-degenerate
constexpr uint32_t kFewestRegularFaces = 4;  // extreme valence below
constexpr uint32_t kMostRegularFaces = 12;   // and above

struct BoundFace {
  Vec3f normal;    // unit
  Vec3f centroid;  // times 3
  bool sliver;
};

inline BoundFace bound_face(const LevelView& m, uint32_t f) {
  const Vec3f p0 = P(m, m.corner_vertex[3 * f]);
  const Vec3f p1 = P(m, m.corner_vertex[3 * f + 1]);
  const Vec3f p2 = P(m, m.corner_vertex[3 * f + 2]);
  const Vec3f e0 = p1 - p0, e1 = p2 - p1, e2 = p2 - p0;
  const float longest =
      std::max(squared_length(e0), std::max(squared_length(e1), squared_length(e2)));
  const Vec3f n = cross(e0, e2);
  const float n2 = squared_length(n);
  BoundFace face;
  // !(>=): a NaN is a sliver too.
  face.sliver = !(n2 >= kSliverQuality * kSliverQuality * longest * longest) || longest == 0.0f;
  face.normal = face.sliver ? Vec3f{} : n / std::sqrt(n2);
  face.centroid = p0 + p1 + p2;
  return face;
}

inline bool extreme_valence(const LevelView& m, uint32_t v) {
  return m.valence[v] < kFewestRegularFaces || m.valence[v] > kMostRegularFaces;
}

// sin(theta / 2) * max(1, L / (sqrt(3) d)) for faces f, g, d the distance
// of their centroids (stored times 3: d = |3 c_f - 3 c_g| / 3).
inline float scaled_sin_half(const BoundFace& f, const BoundFace& g, float edge_length) {
  const float sin_half = length(f.normal - g.normal) * 0.5f;
  const float d = length(f.centroid - g.centroid) * (1.0f / 3.0f);
  if (!(d > 0.0f)) return 1.0f;  // folded faces: the most lenient
  // Only ever more lenient than for equilateral faces.
  const float scale = edge_length / (1.7320508f * d);
  return !(scale > 1.0f) ? sin_half : sin_half * scale;
}

// sigma of an interior edge's stencil, or -1 when the stencil is irregular.
inline float interior_sigma(const LevelView& m, uint32_t c, float edge_length) {
  const uint32_t o = m.opposite[c];
  const uint32_t a = m.corner_vertex[next_corner(c)], b = m.corner_vertex[prev_corner(c)];
  if (m.vertex_features[a] != 0 || m.vertex_features[b] != 0) return -1.0f;
  if (extreme_valence(m, a) || extreme_valence(m, b)) return -1.0f;
  const BoundFace f[2] = {bound_face(m, c / 3), bound_face(m, o / 3)};
  if (f[0].sliver || f[1].sliver) return -1.0f;
  float sigma = scaled_sin_half(f[0], f[1], edge_length);
  const uint32_t side[2] = {c, o};
  for (int k = 0; k < 2; ++k) {
    for (const uint32_t e : {next_corner(side[k]), prev_corner(side[k])}) {
      if (m.feature_edge[e]) continue;  // reflected wing: in the face's plane
      const BoundFace g = bound_face(m, m.opposite[e] / 3);
      if (g.sliver) return -1.0f;
      sigma = std::max(sigma, scaled_sin_half(f[k], g, edge_length));
    }
  }
  return sigma;
}

// sigma of a curve-rule edge: the curve's turning at either endpoint (0 at
// a corner, where the curve is extended straight).
inline float curve_sigma(const LevelView& m, uint32_t c) {
  const uint32_t n = next_corner(c), p = prev_corner(c);
  const uint32_t a = m.corner_vertex[n], b = m.corner_vertex[p];
  const Vec3f A = P(m, a), B = P(m, b);
  const uint32_t xa = m.vertex_features[a] == 2 ? walk_to_feature_ccw(m, n, walk_limit(m)) : kNone;
  const uint32_t xb = m.vertex_features[b] == 2 ? walk_to_feature_cw(m, p, walk_limit(m)) : kNone;
  const Vec3f ab = normalized(B - A), ba = normalized(A - B);
  float sigma = 0.0f;
  if (xa != kNone) sigma = std::max(sigma, length(normalized(A - P(m, xa)) - ab) * 0.5f);
  if (xb != kNone) sigma = std::max(sigma, length(normalized(B - P(m, xb)) - ba) * 0.5f);
  return sigma;
}

// s pulled back to the bound (the slow path: its offset is above L / 8).
[[gnu::noinline]] inline Vec3f bound_far_offset(const LevelView& m, uint32_t c, Vec3f s, Vec3f mid,
                                                float offset2, float length2) {
  const float edge_length = std::sqrt(length2);
  const float sigma = m.feature_edge[c] ? curve_sigma(m, c) : interior_sigma(m, c, edge_length);
  // sigma >= 1 or NaN (no such geometry passes the sliver test) saturates.
  const float limit = edge_length * (kFreeOffset + (sigma < 1.0f ? std::max(sigma, 0.0f) : 1.0f));
  const float offset = std::sqrt(offset2);
  if (offset <= limit) return s;
  return mid + (s - mid) * (limit / offset);
}

// The edge point s of the edge faced by c, whose endpoints are A and B (in
// either order), within the bound.
[[gnu::always_inline]] inline Vec3f bound_offset_between(const LevelView& m, uint32_t c, Vec3f A,
                                                         Vec3f B, Vec3f s) {
  const Vec3f mid = (A + B) * 0.5f;
  const float offset2 = squared_length(s - mid);
  const float length2 = squared_length(B - A);
  if (offset2 <= kFreeOffset * kFreeOffset * length2) return s;
  return bound_far_offset(m, c, s, mid, offset2, length2);
}

// The edge point s of the edge faced by c, within the bound.
[[gnu::always_inline]] inline Vec3f bound_offset(const LevelView& m, uint32_t c, Vec3f s) {
  return bound_offset_between(m, c, P(m, m.corner_vertex[next_corner(c)]),
                              P(m, m.corner_vertex[prev_corner(c)]), s);
}

[[gnu::always_inline]] inline Vec3f edge_point(const LevelView& m, uint32_t c,
                                               const ButterflyWeights& wt,
                                               EdgePlacement placement) {
  Vec3f s = zorin_point(m, c, wt);
  if (placement == EdgePlacement::kProjection && !m.feature_edge[c]) s = project_point(m, c, s);
  return wt.bounds_offsets() ? bound_offset(m, c, s) : s;
}

}  // namespace meshstream::asa::rules
