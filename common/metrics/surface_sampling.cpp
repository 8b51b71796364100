#include "common/metrics/surface_sampling.h"

#include <algorithm>
#include <cmath>

namespace meshstream {
namespace {

// SplitMix64 (S. Vigna): tiny, fast, and the same sequence everywhere.
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

 private:
  uint64_t state_;
};

double triangle_area(Vec3d a, Vec3d b, Vec3d c) { return 0.5 * length(cross(b - a, c - a)); }

}  // namespace

SurfaceSamples sample_surface_area(const Mesh& mesh, uint32_t area_samples, uint64_t seed) {
  SurfaceSamples out;
  const uint32_t faces = mesh.face_count();
  auto corner = [&](uint32_t f, int k) { return to_double(mesh.positions[mesh.triangles[f][k]]); };

  std::vector<double> areas(faces);
  for (uint32_t f = 0; f < faces; ++f) {
    areas[f] = triangle_area(corner(f, 0), corner(f, 1), corner(f, 2));
    out.area += areas[f];
  }

  SplitMix64 rng(seed);
  if (area_samples > 0 && out.area > 0) {
    out.points.reserve(area_samples);
    const double step = out.area / area_samples;
    const double offset = rng.uniform();
    uint32_t last = faces - 1;  // the last triangle with area takes any rounding leftover
    while (areas[last] == 0) --last;
    double start = 0;  // cumulative area before triangle f
    for (uint32_t f = 0; f <= last; ++f) {
      const double end = f == last ? HUGE_VAL : start + areas[f];
      const Vec3d a = corner(f, 0), b = corner(f, 1), c = corner(f, 2);
      while (out.points.size() < area_samples && (out.points.size() + offset) * step < end) {
        // Uniform point in the triangle (Osada et al. 2002, "Shape distributions").
        const double s = std::sqrt(rng.uniform());
        const double r = rng.uniform();
        out.points.push_back(a * (1 - s) + b * (s * (1 - r)) + c * (s * r));
      }
      start = end;
    }
  }
  out.area_count = static_cast<uint32_t>(out.points.size());
  return out;
}

SurfaceSamples sample_surface(const Mesh& mesh, uint32_t area_samples, uint64_t seed) {
  SurfaceSamples out = sample_surface_area(mesh, area_samples, seed);
  const uint32_t faces = mesh.face_count();
  std::vector<uint8_t> referenced(mesh.vertex_count(), 0);
  std::vector<uint64_t> edges;
  edges.reserve(3ull * faces);
  for (const Triangle& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      referenced[t[k]] = 1;
      const uint32_t u = t[k], v = t[(k + 1) % 3];
      edges.push_back(static_cast<uint64_t>(std::min(u, v)) << 32 | std::max(u, v));
    }
  }
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    if (referenced[v]) out.points.push_back(to_double(mesh.positions[v]));
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (uint64_t e : edges) {
    const Vec3d a = to_double(mesh.positions[e >> 32]);
    const Vec3d b = to_double(mesh.positions[e & 0xffffffffu]);
    out.points.push_back((a + b) * 0.5);
  }
  return out;
}

}  // namespace meshstream
