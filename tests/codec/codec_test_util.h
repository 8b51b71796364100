// Procedural meshes and exact comparisons for the codec tests.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <tuple>
#include <vector>

#include "common/mesh/adjacency.h"
#include "common/mesh/mesh.h"
#include "common/mesh/procedural.h"

namespace meshstream::testing {

// Icosphere: make_icosphere (an icosahedron split `levels` times on the unit
// sphere, 10 * 4^levels + 2 vertices). Optional bumps make it non-trivial.
inline Mesh icosphere(int levels, float bump = 0.0f) {
  Mesh m = make_icosphere(static_cast<uint32_t>(levels));
  if (bump == 0) return m;
  for (Vec3f& p : m.positions) p = p * (1.0f + bump * std::sin(5 * p.x) * std::cos(4 * p.y + p.z));
  return m;
}

// Torus (genus 1): a u x v grid wrapped both ways.
inline Mesh torus(int nu, int nv, float R = 1.0f, float r = 0.35f) {
  Mesh m;
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      float a = 2 * float(M_PI) * i / nu, b = 2 * float(M_PI) * j / nv;
      m.positions.push_back({(R + r * std::cos(b)) * std::cos(a),
                             (R + r * std::cos(b)) * std::sin(a), r * std::sin(b)});
    }
  }
  auto id = [&](int i, int j) { return uint32_t(((i + nu) % nu) * nv + (j + nv) % nv); };
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return m;
}

// An open, wavy height field: a boundary loop of 2(n+m) edges.
inline Mesh height_field(int n, int m_) {
  Mesh m;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= m_; ++j) {
      float x = float(i) / n, y = float(j) / m_;
      m.positions.push_back({x, y, 0.1f * std::sin(6 * x) * std::cos(5 * y)});
    }
  auto id = [&](int i, int j) { return uint32_t(i * (m_ + 1) + j); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m_; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

inline Mesh tetrahedron() {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return m;
}

// Several meshes side by side as one (components must all survive).
inline Mesh combine(const std::vector<Mesh>& parts, float spacing = 3.0f) {
  Mesh out;
  for (size_t i = 0; i < parts.size(); ++i) {
    const uint32_t base = out.vertex_count();
    for (Vec3f p : parts[i].positions) out.positions.push_back(p + Vec3f{spacing * float(i), 0, 0});
    for (Triangle t : parts[i].triangles)
      out.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
  return out;
}

// Canonical form of a mesh up to vertex re-indexing: each oriented face as
// its three positions rotated so the smallest comes first, all sorted.
using PositionKey = std::tuple<float, float, float>;
inline std::vector<std::array<PositionKey, 3>> canonical_faces(const Mesh& m) {
  std::vector<std::array<PositionKey, 3>> out;
  for (const Triangle& t : m.triangles) {
    std::array<PositionKey, 3> k;
    for (int i = 0; i < 3; ++i) {
      const Vec3f p = m.positions[t[i]];
      k[i] = {p.x, p.y, p.z};
    }
    // The smallest of the three rotations (ties between equal positions too).
    std::array<PositionKey, 3> best = k;
    for (int r = 0; r < 2; ++r) {
      std::rotate(k.begin(), k.begin() + 1, k.end());
      best = std::min(best, k);
    }
    out.push_back(best);
  }
  std::sort(out.begin(), out.end());
  return out;
}

inline std::vector<PositionKey> sorted_positions(const Mesh& m) {
  std::vector<PositionKey> out;
  for (Vec3f p : m.positions) out.push_back({p.x, p.y, p.z});
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace meshstream::testing
