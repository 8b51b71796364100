// The modified Butterfly rules as inline functions, so the split loops
// (split_uniform.cpp, split_adaptive.cpp) inline them; butterfly_stencils.cpp
// documents the method and every deviation. Internal to common/asa.
#pragma once

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

[[gnu::always_inline]] inline Vec3f edge_point(const LevelView& m, uint32_t c,
                                               const ButterflyWeights& wt,
                                               EdgePlacement placement) {
  const Vec3f s = zorin_point(m, c, wt);
  if (placement == EdgePlacement::kZorin || m.feature_edge[c]) return s;
  return project_point(m, c, s);
}

}  // namespace meshstream::asa::rules
