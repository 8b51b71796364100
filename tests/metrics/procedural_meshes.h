// Small procedural meshes for the metrics tests.
#pragma once

#include <cmath>
#include <map>
#include <utility>

#include "common/mesh/mesh.h"

namespace meshstream::testing {

// The unit square [0,1]^2 at height z, split into 2 x n x n triangles.
inline Mesh grid_square(uint32_t n, float z = 0) {
  Mesh m;
  for (uint32_t j = 0; j <= n; ++j) {
    for (uint32_t i = 0; i <= n; ++i) {
      m.positions.push_back({static_cast<float>(i) / n, static_cast<float>(j) / n, z});
    }
  }
  auto id = [n](uint32_t i, uint32_t j) { return j * (n + 1) + i; };
  for (uint32_t j = 0; j < n; ++j) {
    for (uint32_t i = 0; i < n; ++i) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return m;
}

// An icosahedron subdivided `levels` times, every vertex on the sphere of
// radius `radius` (20 * 4^levels triangles).
inline Mesh icosphere(int levels, float radius = 1) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3d> p = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                          {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                          {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (Vec3d& v : p) v = normalized(v);
  std::vector<Triangle> tris = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      auto key = std::minmax(a, b);
      auto [it, inserted] =
          mid.try_emplace({key.first, key.second}, static_cast<uint32_t>(p.size()));
      if (inserted) p.push_back(normalized(p[a] + p[b]));
      return it->second;
    };
    std::vector<Triangle> next;
    for (const Triangle& f : tris) {
      const uint32_t ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]),
                     ca = midpoint(f[2], f[0]);
      next.push_back({f[0], ab, ca});
      next.push_back({f[1], bc, ab});
      next.push_back({f[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    tris = std::move(next);
  }
  Mesh m;
  for (const Vec3d& v : p) m.positions.push_back(to_float(v * static_cast<double>(radius)));
  m.triangles = std::move(tris);
  return m;
}

inline Mesh scaled(Mesh m, float s) {
  for (Vec3f& v : m.positions) v = v * s;
  return m;
}

}  // namespace meshstream::testing
