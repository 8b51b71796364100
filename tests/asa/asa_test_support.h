// Shared helpers of the ASA tests: procedural meshes, real-mesh loading and
// the conformity check every output must pass.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "common/asa/incremental.h"
#include "common/asa/level_mesh.h"
#include "common/asa/subdivide.h"
#include "common/mesh/adjacency.h"
#include "common/mesh/import.h"
#include "common/mesh/mesh.h"
#include "common/mesh/procedural.h"
#include "tests/test_meshes.h"

namespace meshstream::asa_test {

// A level's positions, triangles and opposite corners from Adjacency (built
// independently of subdivide's corner table); the rest is the caller's.
inline asa::LevelMesh level_with_opposites(const Mesh& mesh) {
  asa::LevelMesh lm;
  auto adj = Adjacency::build(mesh);
  EXPECT_TRUE(adj.has_value());
  lm.positions = mesh.positions;
  lm.triangles = mesh.triangles;
  lm.opposite.resize(3 * mesh.face_count());
  if (adj)
    for (uint32_t c = 0; c < lm.opposite.size(); ++c) lm.opposite[c] = adj->opposite(c);
  return lm;
}

inline Mesh octahedron() {
  Mesh m;
  m.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                 {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return m;
}

inline Mesh icosahedron() { return make_icosahedron(); }

// A flat n x n grid of squares in z = height(x, y), each square split along
// its diagonal: interior vertices have valence 6, the border is a boundary.
template <class Height>
Mesh grid(int n, Height height) {
  Mesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float x = static_cast<float>(i), y = static_cast<float>(j);
      m.positions.push_back({x, y, height(x, y)});
    }
  auto id = [n](int i, int j) { return static_cast<uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}
inline Mesh flat_grid(int n) {
  return grid(n, [](float, float) { return 0.0f; });
}

// Loads a real mesh (tests call MESHSTREAM_REQUIRE_TEST_MESHES() first).
inline Mesh load(const std::string& name) {
  auto imported = import_mesh(::meshstream::testing::test_mesh(name));
  EXPECT_TRUE(imported.has_value()) << name << ": " << (imported ? "" : imported.error().message);
  return imported ? std::move(imported->mesh) : Mesh{};
}

// Every output must be a conforming manifold mesh: the corner table builds,
// a closed input stays closed and an open one gains exactly one boundary edge
// per new boundary vertex (a T-junction would open a hole of three edges
// around its hanging vertex), every vertex is used, and the input's vertices
// are bit-identical.
inline ::testing::AssertionResult conforming(const Mesh& input, const AsaResult& result) {
  const Mesh& out = result.mesh;
  if (result.face_kind.size() != out.triangles.size())
    return ::testing::AssertionFailure() << "face_kind has " << result.face_kind.size()
                                         << " entries for " << out.triangles.size() << " faces";
  if (out.positions.size() < input.positions.size())
    return ::testing::AssertionFailure() << "lost vertices";
  if (std::memcmp(out.positions.data(), input.positions.data(),
                  sizeof(Vec3f) * input.positions.size()) != 0)
    return ::testing::AssertionFailure() << "old vertices moved";
  auto in_adj = Adjacency::build(input);
  auto adj = Adjacency::build(out);
  if (!adj) return ::testing::AssertionFailure() << "output not manifold: " << adj.error().message;
  uint32_t new_boundary = 0;
  for (uint32_t v = 0; v < adj->vertex_count(); ++v) {
    if (adj->is_isolated_vertex(v) && (v >= input.vertex_count() || !in_adj->is_isolated_vertex(v)))
      return ::testing::AssertionFailure() << "vertex " << v << " is not used by any face";
    if (v >= input.vertex_count() && adj->is_boundary_vertex(v)) ++new_boundary;
  }
  if (adj->boundary_edge_count() != in_adj->boundary_edge_count() + new_boundary)
    return ::testing::AssertionFailure() << "boundary edges " << adj->boundary_edge_count()
                                         << " != " << in_adj->boundary_edge_count() << " + "
                                         << new_boundary << " (a T-junction or crack)";
  for (const Vec3f& p : out.positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      return ::testing::AssertionFailure() << "non-finite position";
  return ::testing::AssertionSuccess();
}

// For every vertex >= old_count: its two neighbours below old_count (the
// endpoints of the edge it was made on), kNone where missing.
inline std::vector<std::array<uint32_t, 2>> parents(const std::vector<Triangle>& tris,
                                                    uint32_t old_count, uint32_t count) {
  std::vector<std::array<uint32_t, 2>> p(count - old_count, {kNone, kNone});
  for (const Triangle& t : tris)
    for (int i = 0; i < 3; ++i) {
      uint32_t a = t[i], b = t[(i + 1) % 3];
      for (int pass = 0; pass < 2; ++pass, std::swap(a, b)) {
        if (a >= old_count && b < old_count) {
          auto& slot = p[a - old_count];
          if (slot[0] == kNone)
            slot[0] = b;
          else if (slot[0] != b)
            slot[1] = b;
        }
      }
    }
  return p;
}

// Same faces in the same order with bit-identical corner positions, same
// vertex count, same face kinds.
inline ::testing::AssertionResult same_output(const AsaResult& a, const AsaResult& b) {
  if (a.mesh.face_count() != b.mesh.face_count())
    return ::testing::AssertionFailure()
           << "faces " << a.mesh.face_count() << " vs " << b.mesh.face_count();
  if (a.mesh.vertex_count() != b.mesh.vertex_count())
    return ::testing::AssertionFailure()
           << "vertices " << a.mesh.vertex_count() << " vs " << b.mesh.vertex_count();
  for (uint32_t f = 0; f < a.mesh.face_count(); ++f) {
    for (int i = 0; i < 3; ++i) {
      const Vec3f p = a.mesh.positions[a.mesh.triangles[f][i]],
                  q = b.mesh.positions[b.mesh.triangles[f][i]];
      if (std::memcmp(&p, &q, sizeof p) != 0)
        return ::testing::AssertionFailure() << "face " << f << " corner " << i;
    }
    if (a.face_kind[f] != b.face_kind[f])
      return ::testing::AssertionFailure() << "face kind of " << f;
  }
  return ::testing::AssertionSuccess();
}

inline uint32_t edge_count(const Mesh& m) {
  auto adj = Adjacency::build(m);
  return adj ? adj->edge_count() : 0;
}

// Each face as its corners' position bits and its kind, sorted: the mesh's
// faces as a set (vertex numbering and face order left out).
// Kinds left out (0) when `kinds` is null.
inline std::vector<std::array<uint32_t, 10>> face_set(const Mesh& m,
                                                      const std::vector<FaceKind>* kinds) {
  std::vector<std::array<uint32_t, 10>> keys;
  keys.reserve(m.face_count());
  for (uint32_t f = 0; f < m.face_count(); ++f) {
    std::array<uint32_t, 10> k{};
    for (int i = 0; i < 3; ++i) std::memcpy(&k[3 * i], &m.positions[m.triangles[f][i]], 12);
    k[9] = kinds ? static_cast<uint32_t>((*kinds)[f]) : 0;
    keys.push_back(k);
  }
  std::sort(keys.begin(), keys.end());
  return keys;
}
inline std::vector<std::array<uint32_t, 10>> face_set(const AsaResult& r) {
  return face_set(r.mesh, &r.face_kind);
}

// The incremental subdivider's in-place result against a full run: face
// for face once put in subdivide()'s order (canonical()), and the in-place
// faces themselves the same set of triangles (corner positions bit for bit,
// corner order, kinds), every index in range.
inline ::testing::AssertionResult same_incremental(const IncrementalSubdivider& inc,
                                                   const AsaResult& full) {
  const AsaResult canonical = inc.canonical();
  if (auto same = same_output(canonical, full); !same) return same << " (canonical order)";
  const AsaResult& in_place = inc.result();
  if (in_place.face_kind.size() != in_place.mesh.face_count() ||
      in_place.source_face.size() != in_place.mesh.face_count())
    return ::testing::AssertionFailure() << "per-face arrays of the in-place result";
  for (const Triangle& t : in_place.mesh.triangles)
    for (uint32_t v : t)
      if (v >= in_place.mesh.vertex_count())
        return ::testing::AssertionFailure() << "in-place face refers to vertex " << v;
  if (face_set(in_place) != face_set(full))
    return ::testing::AssertionFailure() << "in-place faces differ from the full run's as a set";
  return ::testing::AssertionSuccess();
}

// conforming() of the canonical result, and of the in-place mesh itself:
// manifold, the same boundary edges, the input's vertices in their slots,
// unused vertex slots within the subdivider's bound.
inline ::testing::AssertionResult conforming_incremental(const Mesh& input,
                                                         const IncrementalSubdivider& inc) {
  const AsaResult canonical = inc.canonical();
  if (auto ok = conforming(input, canonical); !ok) return ok << " (canonical)";
  const Mesh& out = inc.result().mesh;
  if (out.positions.size() < input.positions.size() ||
      std::memcmp(out.positions.data(), input.positions.data(),
                  sizeof(Vec3f) * input.positions.size()) != 0)
    return ::testing::AssertionFailure() << "in place: input vertices not in their slots";
  auto adj = Adjacency::build(out);
  auto canonical_adj = Adjacency::build(canonical.mesh);
  if (!adj)
    return ::testing::AssertionFailure() << "in place not manifold: " << adj.error().message;
  if (!canonical_adj || adj->boundary_edge_count() != canonical_adj->boundary_edge_count())
    return ::testing::AssertionFailure() << "in place: boundary edges differ";
  const uint32_t unused = out.vertex_count() - canonical.mesh.vertex_count();
  if (unused != inc.unused_vertices())
    return ::testing::AssertionFailure()
           << unused << " unused vertex slots, unused_vertices() says " << inc.unused_vertices();
  const uint32_t bound = (inc.input_slots() - input.vertex_count()) + 1024 + out.vertex_count() / 8;
  if (unused > bound)
    return ::testing::AssertionFailure() << unused << " unused vertex slots, bound " << bound;
  return ::testing::AssertionSuccess();
}

// A decoder-like refinement: a new vertex inside face f, lifted off the
// plane; f is replaced in place and two faces are appended.
inline void insert_vertex(Mesh& m, uint32_t f, float lift) {
  const Triangle t = m.triangles[f];
  const Vec3f a = m.positions[t[0]], b = m.positions[t[1]], c = m.positions[t[2]];
  const Vec3f n = normalized(cross(b - a, c - a));
  const float size = length(b - a);
  const uint32_t v = m.vertex_count();
  m.positions.push_back((a + b + c) / 3.0f + n * (lift * size));
  if (!m.colors.empty()) m.colors.push_back({0.5f, 0.5f, 0.5f, 1});
  m.triangles[f] = {t[0], t[1], v};
  m.triangles.push_back({t[1], t[2], v});
  m.triangles.push_back({t[2], t[0], v});
}

}  // namespace meshstream::asa_test
