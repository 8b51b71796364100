// Small procedural meshes for the metrics tests.
#pragma once

#include <cmath>
#include <map>
#include <utility>

#include "common/mesh/mesh.h"
#include "common/mesh/procedural.h"

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

inline Mesh scaled(Mesh m, float s) {
  for (Vec3f& v : m.positions) v = v * s;
  return m;
}

// make_icosphere (an icosahedron subdivided `levels` times, 20 * 4^levels
// triangles) on the sphere of radius `radius`.
inline Mesh icosphere(int levels, float radius = 1) {
  return scaled(make_icosphere(static_cast<uint32_t>(levels)), radius);
}

}  // namespace meshstream::testing
