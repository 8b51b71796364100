// Layered decimation (common/codec/decimate.h): the base target rule and the
// cost's preference for removals that do not change the surface.
#include "common/codec/decimate.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "common/codec/encoder.h"
#include "common/codec/quantize.h"
#include "common/mesh/procedural.h"

namespace meshstream {
namespace {

// A unit cube whose faces are s x s grids (6 s^2 + 2 vertices): flat faces
// and sharp creases, like a CAD part. Outward oriented.
Mesh subdivided_cube(int s) {
  Mesh m;
  std::map<std::array<int, 3>, uint32_t> id;
  auto vertex = [&](std::array<int, 3> c) {
    auto [it, fresh] = id.try_emplace(c, m.vertex_count());
    if (fresh) m.positions.push_back({float(c[0]) / s, float(c[1]) / s, float(c[2]) / s});
    return it->second;
  };
  for (int a = 0; a < 3; ++a) {
    const int u = (a + 1) % 3, w = (a + 2) % 3;  // e_u x e_w = e_a
    for (int side : {0, s}) {
      for (int i = 0; i < s; ++i) {
        for (int j = 0; j < s; ++j) {
          auto corner = [&](int di, int dj) {
            std::array<int, 3> c{};
            c[a] = side;
            c[u] = i + di;
            c[w] = j + dj;
            return vertex(c);
          };
          const uint32_t p00 = corner(0, 0), p10 = corner(1, 0), p11 = corner(1, 1),
                         p01 = corner(0, 1);
          if (side == s) {
            m.triangles.push_back({p00, p10, p11});
            m.triangles.push_back({p00, p11, p01});
          } else {
            m.triangles.push_back({p00, p11, p10});
            m.triangles.push_back({p00, p01, p11});
          }
        }
      }
    }
  }
  return m;
}

struct Measures {
  double volume = 0, area = 0;
};
// Enclosed volume (divergence theorem) and area, on grid coordinates.
Measures measures(const std::vector<Vec3i>& p, const std::vector<Triangle>& faces) {
  Measures out;
  for (const Triangle& t : faces) {
    const Vec3d a{double(p[t[0]].x), double(p[t[0]].y), double(p[t[0]].z)};
    const Vec3d b{double(p[t[1]].x), double(p[t[1]].y), double(p[t[1]].z)};
    const Vec3d c{double(p[t[2]].x), double(p[t[2]].y), double(p[t[2]].z)};
    out.volume += dot(a, cross(b, c)) / 6;
    out.area += length(cross(b - a, c - a)) / 2;
  }
  return out;
}

// `mesh` on a 12-bit grid, decimated with `options`: what the tests look at.
struct GridDecimation {
  QuantGrid grid;
  std::vector<Vec3i> q;  // grid positions, by input id
  DecimationResult result;
};
std::optional<GridDecimation> decimate_on_grid(const Mesh& mesh, const DecimateOptions& options) {
  auto grid = make_grid(mesh, 12);
  if (!grid) {
    ADD_FAILURE() << grid.error().message;
    return std::nullopt;
  }
  GridDecimation out{*grid, quantize_positions(mesh, *grid), {}};
  auto editable = EditableMesh::build(out.q, mesh.triangles);
  if (!editable) {
    ADD_FAILURE() << editable.error().message;
    return std::nullopt;
  }
  out.result = decimate_layers(std::move(*editable), options);
  return out;
}

TEST(Decimate, BaseTargetShrinksForSmallMeshesOnly) {
  DecimateOptions share;
  share.max_base_share = 1.0 / 16;
  EXPECT_EQ(base_target(100000, share), 300u);         // large: the fixed target
  EXPECT_EQ(base_target(4800, share), 300u);           // 1/16 of it is exactly 300
  EXPECT_EQ(base_target(1861, share), 116u);           // hemisphere.off: 1/16
  EXPECT_EQ(base_target(300, share), kMinBaseTarget);  // never below the floor
  const DecimateOptions off;                           // the default (see DecimateOptions)
  EXPECT_EQ(base_target(1861, off), 300u);
  share.target_vertices = 50;
  EXPECT_EQ(base_target(1861, share), 50u);
}

// The share rule inside decimate_layers: a small mesh stops at 1/16 of its
// vertices instead of the fixed target.
TEST(Decimate, SmallMeshBaseHoldsItsShare) {
  const Mesh cube = subdivided_cube(10);  // 602 vertices: 1/16 = 37
  DecimateOptions options;
  options.max_base_share = 1.0 / 16;
  const auto decimated = decimate_on_grid(cube, options);
  ASSERT_TRUE(decimated);
  const DecimationResult& dec = decimated->result;
  EXPECT_EQ(dec.base_vertices.size(), 37u);
  EXPECT_FALSE(dec.layers.empty());
}

// A CAD-like cube: every vertex but the 8 corners can go with zero error
// (inside a flat face, or along a straight crease into a crease
// neighbour). The decimation reaches a small target and the base is still
// exactly the cube: volume and area unchanged on the grid.
TEST(Decimate, FlatFacesAndCreasesDecimateWithoutError) {
  const Mesh cube = subdivided_cube(16);
  ASSERT_EQ(cube.vertex_count(), 6u * 16 * 16 + 2);
  DecimateOptions options;
  options.target_vertices = 96;  // 1 538 vertices: many layers, all exact
  const auto decimated = decimate_on_grid(cube, options);
  ASSERT_TRUE(decimated);
  const std::vector<Vec3i>& q = decimated->q;
  const DecimationResult& dec = decimated->result;
  EXPECT_EQ(dec.base_vertices.size(), 96u);
  const Measures before = measures(q, cube.triangles);
  const Measures after = measures(q, dec.base_faces);
  EXPECT_NEAR(after.volume, before.volume, 1e-9 * before.volume);
  EXPECT_NEAR(after.area, before.area, 1e-9 * before.area);
  // The corners, the only vertices whose every removal cuts the cube, stay.
  int corners = 0;
  for (uint32_t v : dec.base_vertices) {
    const Vec3i p = q[v];
    const int m = decimated->grid.max_coordinate();
    corners += (p.x == 0 || p.x == m) && (p.y == 0 || p.y == m) && (p.z == 0 || p.z == m);
  }
  EXPECT_EQ(corners, 8);
}

// A flat square with one bump: the flat part is removable at no cost, so
// the coarse mesh spends its vertices on the bump (area-weighted quadric
// error: a large flat star costs nothing, a small curved one does).
TEST(Decimate, CoarseVerticesGoWhereTheSurfaceBends) {
  const int n = 41;
  Mesh m;
  const double cx = 30, cy = 30, r = 6;
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const double d2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
      const float z = d2 < r * r ? float(4.0 * std::pow(1 - d2 / (r * r), 2)) : 0.0f;
      m.positions.push_back({float(x), float(y), z});
    }
  }
  for (int y = 0; y + 1 < n; ++y) {
    for (int x = 0; x + 1 < n; ++x) {
      const uint32_t a = y * n + x, b = a + 1, c = a + n + 1, d = a + n;
      m.triangles.push_back({a, b, c});
      m.triangles.push_back({a, c, d});
    }
  }
  DecimateOptions options;
  options.target_vertices = 100;
  const auto decimated = decimate_on_grid(m, options);
  ASSERT_TRUE(decimated);
  const std::vector<Vec3i>& q = decimated->q;
  const DecimationResult& dec = decimated->result;
  ASSERT_EQ(dec.base_vertices.size(), 100u);
  int on_bump = 0;
  for (uint32_t v : dec.base_vertices) {
    const double x = m.positions[v].x, y = m.positions[v].y;
    on_bump += (x - cx) * (x - cx) + (y - cy) * (y - cy) <= (r + 1) * (r + 1);
  }
  // The bump's disk (with a cell of margin) is under 10 % of the square's
  // area; the flat part needs only its 4 corners.
  EXPECT_GE(on_bump, 50) << "base vertices on the bump: " << on_bump << " of 100";
  // The square's outline is kept (boundary planes in the quadrics): its
  // four corners stay.
  int square_corners = 0;
  for (uint32_t v : dec.base_vertices) {
    const Vec3i p = q[v];
    square_corners += (p.x == 0 || p.x == q[n - 1].x) && (p.y == 0 || p.y == q[n * (n - 1)].y);
  }
  EXPECT_EQ(square_corners, 4);
}

// The candidate share bounds a layer's size: drawn from every candidate, a
// layer removes more vertices than from the cheapest half (the default), so
// the same base takes fewer layers. The encoder refuses shares outside (0, 1].
TEST(Decimate, CandidateShareBoundsTheLayerSize) {
  const Mesh cube = subdivided_cube(12);  // 866 vertices
  DecimateOptions options;
  options.target_vertices = 100;
  auto first_layer_and_count = [&](double share) {
    options.candidate_share = share;
    const auto decimated = decimate_on_grid(cube, options);
    EXPECT_TRUE(decimated);
    EXPECT_EQ(decimated->result.base_vertices.size(), 100u) << share;
    return std::pair{decimated->result.layers.at(0).removals.size(),
                     decimated->result.layers.size()};
  };
  const auto [half_first, half_layers] = first_layer_and_count(kDefaultCandidateShare);
  const auto [all_first, all_layers] = first_layer_and_count(1.0);
  EXPECT_GT(all_first, half_first);
  EXPECT_LT(all_layers, half_layers);

  EncodeOptions encode;
  for (double share : {0.0, -0.5, 1.5}) {
    encode.layer_candidate_share = share;
    auto refused = encode_hcs(cube, encode);
    ASSERT_FALSE(refused) << share;
    EXPECT_EQ(refused.error().code, ErrorCode::kInvalidArgument) << share;
  }
}

}  // namespace
// The removals are the same whatever the thread count: the costs and the
// sort of the cheapest candidates (split over threads above 16k of them)
// run on the threads, the removals on the calling one. A flat-faced cube
// (most costs tie at zero, so the vertex id orders them) and a curved
// surface, both big enough for the split sort.
TEST(Decimate, TheLayersAreTheSameForEveryThreadCount) {
  for (const Mesh& mesh : {subdivided_cube(80), make_demo_mesh(80'000)}) {
    ASSERT_GT(mesh.vertex_count(), 2u * 16384);
    DecimateOptions one;
    one.threads = 1;
    const auto reference = decimate_on_grid(mesh, one);
    ASSERT_TRUE(reference);
    const DecimationResult& ref = reference->result;
    ASSERT_GT(ref.layers.size(), 3u);
    for (unsigned threads : {2u, 3u}) {
      DecimateOptions options;
      options.threads = threads;
      const auto decimated = decimate_on_grid(mesh, options);
      ASSERT_TRUE(decimated);
      const DecimationResult& dec = decimated->result;
      ASSERT_EQ(dec.layers.size(), ref.layers.size()) << threads << " threads";
      for (size_t l = 0; l < ref.layers.size(); ++l) {
        const DecimationLayer& a = ref.layers[l];
        const DecimationLayer& b = dec.layers[l];
        ASSERT_EQ(b.removals.size(), a.removals.size()) << "layer " << l;
        for (size_t i = 0; i < a.removals.size(); ++i) {
          EXPECT_EQ(b.removals[i].vertex, a.removals[i].vertex);
          EXPECT_EQ(b.removals[i].ring_first, a.removals[i].ring_first);
          EXPECT_EQ(b.removals[i].ring_size, a.removals[i].ring_size);
          EXPECT_EQ(b.removals[i].open_edge, a.removals[i].open_edge);
        }
        EXPECT_EQ(b.rings, a.rings) << "layer " << l;
      }
      EXPECT_EQ(dec.base_vertices, ref.base_vertices);
      EXPECT_EQ(dec.base_faces, ref.base_faces);
    }
  }
}

}  // namespace meshstream
