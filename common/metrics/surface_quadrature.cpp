#include "common/metrics/surface_quadrature.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/base/parallel_blocks.h"

namespace meshstream {

namespace {

template <class EachFace>
WeightedSamples quadrature_of(const Mesh& mesh, double cell_area, const EachFace& each_face) {
  WeightedSamples out;
  each_face([&](const Triangle& t) {
    const Vec3f& fa = mesh.positions[t[0]];
    const Vec3f& fb = mesh.positions[t[1]];
    const Vec3f& fc = mesh.positions[t[2]];
    const Vec3d a{fa.x, fa.y, fa.z};
    const Vec3d u{double(fb.x) - fa.x, double(fb.y) - fa.y, double(fb.z) - fa.z};
    const Vec3d v{double(fc.x) - fa.x, double(fc.y) - fa.y, double(fc.z) - fa.z};
    const double cx = u.y * v.z - u.z * v.y, cy = u.z * v.x - u.x * v.z, cz = u.x * v.y - u.y * v.x;
    const double area = 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
    if (!(area > 0)) return;
    const int k = static_cast<int>(std::clamp(std::ceil(std::sqrt(area / cell_area)), 1.0, 32.0));
    const double w = area / (double(k) * k);
    auto add = [&](double s, double r) {  // barycentric (1 - s - r, s, r)
      out.points.push_back(
          {a.x + s * u.x + r * v.x, a.y + s * u.y + r * v.y, a.z + s * u.z + r * v.z});
      out.weights.push_back(w);
    };
    for (int i = 0; i < k; ++i) {
      for (int j = 0; i + j < k; ++j) {
        add((i + 1.0 / 3) / k, (j + 1.0 / 3) / k);                     // upward sub-triangle
        if (i + j < k - 1) add((i + 2.0 / 3) / k, (j + 2.0 / 3) / k);  // downward neighbour
      }
    }
    out.area += area;
  });
  return out;
}

}  // namespace

WeightedSamples quadrature_samples(const Mesh& mesh, double cell_area) {
  return quadrature_of(mesh, cell_area, [&](const auto& visit) {
    for (const Triangle& t : mesh.triangles) visit(t);
  });
}

WeightedSamples quadrature_samples(const Mesh& mesh, double cell_area,
                                   const std::vector<uint32_t>& faces) {
  return quadrature_of(mesh, cell_area, [&](const auto& visit) {
    for (uint32_t f : faces) visit(mesh.triangles[f]);
  });
}

double weighted_rms_distance(const WeightedSamples& from, const TriangleBvh& to, unsigned threads) {
  // Fixed blocks, each summed in order and the block sums added in order:
  // the same result for every thread count.
  constexpr size_t kBlock = 8192;
  const size_t blocks = (from.points.size() + kBlock - 1) / kBlock;
  std::vector<double> sums(blocks, 0.0), weights(blocks, 0.0);
  auto run_block = [&](size_t b) {
    uint32_t hint = TriangleBvh::kNoHint;
    const size_t end = std::min(from.points.size(), (b + 1) * kBlock);
    for (size_t i = b * kBlock; i < end; ++i) {
      const ClosestHit hit = to.closest(from.points[i], hint);
      hint = hit.triangle;
      sums[b] += from.weights[i] * hit.squared_distance;
      weights[b] += from.weights[i];
    }
  };
  for_each_block(blocks, threads, run_block);
  double sum = 0, weight = 0;
  for (size_t b = 0; b < blocks; ++b) {
    sum += sums[b];
    weight += weights[b];
  }
  return weight > 0 ? std::sqrt(sum / weight) : 0;
}

}  // namespace meshstream
