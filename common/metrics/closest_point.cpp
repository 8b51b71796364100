#include "common/metrics/closest_point.h"

#include <algorithm>

namespace meshstream {

Vec3d closest_point_on_segment(Vec3d p, Vec3d a, Vec3d b) {
  const Vec3d ab = b - a;
  const double len2 = dot(ab, ab);
  if (!(len2 > 0)) return a;
  const double t = std::clamp(dot(p - a, ab) / len2, 0.0, 1.0);
  return a + ab * t;
}

namespace {

Vec3d closest_on_edges(Vec3d p, Vec3d a, Vec3d b, Vec3d c) {
  Vec3d best = closest_point_on_segment(p, a, b);
  double best_d2 = squared_length(p - best);
  for (Vec3d q : {closest_point_on_segment(p, b, c), closest_point_on_segment(p, c, a)}) {
    const double d2 = squared_length(p - q);
    if (d2 < best_d2) {
      best = q;
      best_d2 = d2;
    }
  }
  return best;
}

}  // namespace

Vec3d closest_point_on_triangle(Vec3d p, Vec3d a, Vec3d b, Vec3d c) {
  const Vec3d ab = b - a;
  const Vec3d ac = c - a;
  // Ericson's region tests divide by edge projections and by the (scaled)
  // area; on a sliver they are 0/0. Such a triangle is, to rounding, its edges.
  const Vec3d n = cross(ab, ac);
  if (!(dot(n, n) > 1e-24 * dot(ab, ab) * dot(ac, ac))) return closest_on_edges(p, a, b, c);

  // Vertex region of a.
  const Vec3d ap = p - a;
  const double d1 = dot(ab, ap);
  const double d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;

  // Vertex region of b.
  const Vec3d bp = p - b;
  const double d3 = dot(ab, bp);
  const double d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;

  // Edge region of ab.
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));

  // Vertex region of c.
  const Vec3d cp = p - c;
  const double d5 = dot(ab, cp);
  const double d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;

  // Edge region of ac.
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));

  // Edge region of bc.
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }

  // Face region: barycentric coordinates (u, v, w) = (va, vb, vc) / sum.
  const double sum = va + vb + vc;
  if (!(sum > 0)) return closest_on_edges(p, a, b, c);
  const double denom = 1.0 / sum;
  return a + ab * (vb * denom) + ac * (vc * denom);
}

double squared_distance_to_box(Vec3d p, Vec3d lo, Vec3d hi) {
  double gap[3];
  for (int i = 0; i < 3; ++i) {
    if (p[i] < lo[i]) {
      gap[i] = p[i] - lo[i];
    } else if (p[i] > hi[i]) {
      gap[i] = p[i] - hi[i];
    } else {
      gap[i] = 0;
    }
  }
  return gap[0] * gap[0] + gap[1] * gap[1] + gap[2] * gap[2];
}

}  // namespace meshstream
