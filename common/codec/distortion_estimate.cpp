// Distortion estimate: see distortion_estimate.h.
#include "common/codec/distortion_estimate.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/metrics/closest_point.h"

namespace meshstream {
namespace {

Vec3d grid_point(Vec3i p) { return {double(p.x), double(p.y), double(p.z)}; }

}  // namespace

double displacement_error2(Vec3i recon, Vec3i truth) {
  const double e[3] = {double(recon.x) - truth.x, double(recon.y) - truth.y,
                       double(recon.z) - truth.z};
  return e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
}

double vertex_error2(EncoderTruth& t, uint32_t v, Vec3i recon) {
  if (!t.surface) return displacement_error2(recon, t.position[v]);
  if (recon == t.position[v]) return 0;  // an original vertex lies on the original surface
  if (t.cached.size() <= v) t.cached.resize(v + 1);
  EncoderTruth::CachedError& c = t.cached[v];
  for (int i = 0; i < 2; ++i)
    if (c.error2[i] >= 0 && c.position[i] == recon) return c.error2[i];
  const ClosestHit hit = t.surface->closest(grid_point(recon), c.triangle);
  c.triangle = hit.triangle;
  c.position[1] = c.position[0];
  c.error2[1] = c.error2[0];
  c.position[0] = recon;
  c.error2[0] = hit.squared_distance;
  return hit.squared_distance;
}

double fan_distance2(const std::vector<Vec3i>& pos, const std::vector<uint32_t>& ring, Vec3i p) {
  const Vec3d q = grid_point(p);
  double best = std::numeric_limits<double>::infinity();
  const Vec3d a = grid_point(pos[ring[0]]);
  for (size_t i = 1; i + 1 < ring.size(); ++i) {
    const Vec3d c =
        closest_point_on_triangle(q, a, grid_point(pos[ring[i]]), grid_point(pos[ring[i + 1]]));
    const double dx = c.x - q.x, dy = c.y - q.y, dz = c.z - q.z;
    best = std::min(best, dx * dx + dy * dy + dz * dz);
  }
  return best;
}

double ring_area(const std::vector<Vec3i>& p, const std::vector<uint32_t>& ring) {
  double total = 0;
  const Vec3i o = p[ring[0]];
  for (size_t i = 1; i + 1 < ring.size(); ++i) {
    const Vec3i a = p[ring[i]], b = p[ring[i + 1]];
    const double ax = a.x - o.x, ay = a.y - o.y, az = a.z - o.z;
    const double bx = b.x - o.x, by = b.y - o.y, bz = b.z - o.z;
    const double cx = ay * bz - az * by, cy = az * bx - ax * bz, cz = ax * by - ay * bx;
    total += 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
  }
  return total;
}

std::vector<Vec3f> vertex_normals(const std::vector<Vec3i>& q, const std::vector<Triangle>& faces) {
  std::vector<Vec3f> n(q.size(), Vec3f{0, 0, 0});
  for (const Triangle& t : faces) {
    const Vec3i a = q[t[0]], b = q[t[1]], c = q[t[2]];
    const double ux = b.x - a.x, uy = b.y - a.y, uz = b.z - a.z;
    const double wx = c.x - a.x, wy = c.y - a.y, wz = c.z - a.z;
    const Vec3f cr{float(uy * wz - uz * wy), float(uz * wx - ux * wz), float(ux * wy - uy * wx)};
    for (uint32_t v : t) n[v] = n[v] + cr;
  }
  for (Vec3f& x : n) {
    const float len = std::sqrt(x.x * x.x + x.y * x.y + x.z * x.z);
    x = len > 0 ? Vec3f{x.x / len, x.y / len, x.z / len} : Vec3f{0, 0, 1};
  }
  return n;
}

}  // namespace meshstream
