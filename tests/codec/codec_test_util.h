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

namespace meshstream::testing {

// Icosphere: an icosahedron split `levels` times, projected to the unit
// sphere (10 * 4^levels + 2 vertices). Optional bumps make it non-trivial.
inline Mesh icosphere(int levels, float bump = 0.0f) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  Mesh m;
  m.positions = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      Vec3f p = (m.positions[a] + m.positions[b]) * 0.5f;
      m.positions.push_back(p);
      return mid[key] = static_cast<uint32_t>(m.positions.size() - 1);
    };
    std::vector<Triangle> next;
    for (const Triangle& tri : m.triangles) {
      uint32_t ab = midpoint(tri[0], tri[1]), bc = midpoint(tri[1], tri[2]),
               ca = midpoint(tri[2], tri[0]);
      next.push_back({tri[0], ab, ca});
      next.push_back({tri[1], bc, ab});
      next.push_back({tri[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    m.triangles = std::move(next);
  }
  for (Vec3f& p : m.positions) {
    p = normalized(p);
    if (bump != 0) p = p * (1.0f + bump * std::sin(5 * p.x) * std::cos(4 * p.y + p.z));
  }
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
