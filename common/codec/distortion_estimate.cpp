// Distortion estimate: see distortion_estimate.h.
#include "common/codec/distortion_estimate.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/metrics/closest_point.h"

namespace meshstream {
double displacement_error2(Vec3i recon, Vec3i truth) {
  return squared_length(to_double(recon - truth));
}

namespace {

// `p` as an offset from `truth`, 10 bits an axis (|offset| < 512), as one
// integer below 2^30; kNoKey when an axis is farther (never looked up).
constexpr int32_t kOffsetReach = 512;
uint32_t offset_key(Vec3i p, Vec3i truth) {
  uint32_t key = 0;
  for (int a = 0; a < 3; ++a) {
    const int64_t d = int64_t(p[a]) - int64_t(truth[a]) + kOffsetReach;
    if (d < 0 || d >= 2 * kOffsetReach) return EncoderTruth::CachedError::kNoKey;
    key |= uint32_t(d) << (10 * a);
  }
  return key;
}

}  // namespace

double vertex_error2(EncoderTruth& t, uint32_t v, Vec3i recon) {
  const Vec3i truth = t.position(v);
  if (!t.surface) return displacement_error2(recon, truth);
  if (recon == truth) return 0;  // an original vertex lies on the original surface
  if (t.cached.size() <= v) t.cached.resize(v + 1);
  EncoderTruth::CachedError& c = t.cached[v];
  const uint32_t key = offset_key(recon, truth);
  if (key != EncoderTruth::CachedError::kNoKey)
    for (int i = 0; i < 2; ++i)
      if (c.position[i] == key) return c.error2[i];
  const ClosestHit hit = t.surface->closest_from_slot(to_double(recon), c.slot);
  c.slot = hit.slot;
  c.position[1] = c.position[0];
  c.error2[1] = c.error2[0];
  c.position[0] = key;
  c.error2[0] = hit.squared_distance;
  return hit.squared_distance;
}

double fan_distance2(const std::vector<Vec3i>& pos, const std::vector<uint32_t>& ring, Vec3i p) {
  const Vec3d q = to_double(p);
  double best = std::numeric_limits<double>::infinity();
  const Vec3d a = to_double(pos[ring[0]]);
  for (size_t i = 1; i + 1 < ring.size(); ++i) {
    const Vec3d c =
        closest_point_on_triangle(q, a, to_double(pos[ring[i]]), to_double(pos[ring[i + 1]]));
    best = std::min(best, squared_length(c - q));
  }
  return best;
}

double ring_area(const std::vector<Vec3i>& p, const std::vector<uint32_t>& ring) {
  double total = 0;
  const Vec3i o = p[ring[0]];
  for (size_t i = 1; i + 1 < ring.size(); ++i) {
    total += 0.5 * length(cross(to_double(p[ring[i]] - o), to_double(p[ring[i + 1]] - o)));
  }
  return total;
}

std::vector<Vec3f> vertex_normals(const std::vector<Vec3i>& q, const std::vector<Triangle>& faces) {
  std::vector<Vec3f> n(q.size(), Vec3f{0, 0, 0});
  for (const Triangle& t : faces) {
    const Vec3i a = q[t[0]];
    const Vec3f cr = to_float(cross(to_double(q[t[1]] - a), to_double(q[t[2]] - a)));
    for (uint32_t v : t) n[v] += cr;
  }
  for (Vec3f& x : n) {
    const float len = length(x);
    x = len > 0 ? x / len : Vec3f{0, 0, 1};
  }
  return n;
}

}  // namespace meshstream
