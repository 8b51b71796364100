#include "common/mesh/procedural.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

namespace meshstream {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr uint32_t kNoValue = 0xFFFFFFFFu;

// ---- Gradient noise (Perlin, "Improving noise", SIGGRAPH 2002), with an
// integer hash instead of a permutation table so it needs no state.
uint32_t hash3(int32_t x, int32_t y, int32_t z) {
  uint32_t h = static_cast<uint32_t>(x) * 0x8da6b343u ^ static_cast<uint32_t>(y) * 0xd8163841u ^
               static_cast<uint32_t>(z) * 0xcb1ab31fu;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}

double gradient(uint32_t h, double x, double y, double z) {
  // The 12 edge directions of a cube, as in Perlin 2002.
  switch (h % 12) {
    case 0:
      return x + y;
    case 1:
      return -x + y;
    case 2:
      return x - y;
    case 3:
      return -x - y;
    case 4:
      return x + z;
    case 5:
      return -x + z;
    case 6:
      return x - z;
    case 7:
      return -x - z;
    case 8:
      return y + z;
    case 9:
      return -y + z;
    case 10:
      return y - z;
    default:
      return -y - z;
  }
}

double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }
double lerp(double a, double b, double t) { return a + t * (b - a); }

// Roughly in [-1, 1].
double noise(Vec3d p) {
  const double fx = std::floor(p.x), fy = std::floor(p.y), fz = std::floor(p.z);
  const int32_t X = static_cast<int32_t>(fx), Y = static_cast<int32_t>(fy),
                Z = static_cast<int32_t>(fz);
  const double x = p.x - fx, y = p.y - fy, z = p.z - fz;
  const double u = fade(x), v = fade(y), w = fade(z);
  auto g = [&](int dx, int dy, int dz) {
    return gradient(hash3(X + dx, Y + dy, Z + dz), x - dx, y - dy, z - dz);
  };
  return lerp(lerp(lerp(g(0, 0, 0), g(1, 0, 0), u), lerp(g(0, 1, 0), g(1, 1, 0), u), v),
              lerp(lerp(g(0, 0, 1), g(1, 0, 1), u), lerp(g(0, 1, 1), g(1, 1, 1), u), v), w);
}

// ---- The trefoil: (2,3) torus knot on a torus of radii 1 and 0.45.
Vec3d knot(double t) {
  const double r = 1.0 + 0.45 * std::cos(3 * t);
  return {r * std::cos(2 * t), r * std::sin(2 * t), 0.45 * std::sin(3 * t)};
}

// Frenet-like frame from numerical derivatives; periodic because the curve
// is, and well defined because a torus knot has no inflection points.
struct Frame {
  Vec3d origin, tangent, normal, binormal;
};

Frame frame_at(double t) {
  const double h = 1e-4;
  const Vec3d p = knot(t);
  const Vec3d d1 = (knot(t + h) - knot(t - h)) / (2 * h);
  const Vec3d d2 = (knot(t + h) - 2.0 * p + knot(t - h)) / (h * h);
  const Vec3d tangent = normalized(d1);
  const Vec3d normal = normalized(d2 - tangent * dot(d2, tangent));
  return {p, tangent, normal, cross(tangent, normal)};
}

// Tube radius at knot parameter t (0..2pi), angle a around the tube, and the
// un-displaced surface point p: the features at several scales.
double tube_radius(double t, double a, Vec3d p) {
  const double base = 0.16;
  // Broad: three bulges along the knot.
  const double broad = 0.35 * std::sin(3 * t + 0.5) + 0.12 * std::cos(5 * t);
  // Medium: ridges every 1/40 of the length, twisting around the tube.
  const double phase = 40 * t + 2 * a;
  const double ridge = std::pow(std::abs(std::sin(phase)), 6.0) * 0.10;
  // Fine: two octaves of gradient noise on the surface.
  const double fine = 0.08 * noise(p * 9.0) + 0.04 * noise(p * 23.0 + Vec3d{5.2, 1.3, 7.7});
  return base * (1 + broad + ridge + fine);
}

void add_quad_grid_faces(Mesh& mesh, uint32_t rows, uint32_t cols, bool wrap_rows, bool wrap_cols,
                         uint32_t offset = 0) {
  // Vertex (i, j) = offset + i * cols + j, for grids closed in either direction.
  const uint32_t row_cells = wrap_rows ? rows : rows - 1;
  const uint32_t col_cells = wrap_cols ? cols : cols - 1;
  for (uint32_t i = 0; i < row_cells; ++i) {
    for (uint32_t j = 0; j < col_cells; ++j) {
      const uint32_t i1 = (i + 1) % rows, j1 = (j + 1) % cols;
      const uint32_t a = offset + i * cols + j, b = offset + i1 * cols + j;
      const uint32_t c = offset + i1 * cols + j1, d = offset + i * cols + j1;
      mesh.triangles.push_back({a, b, c});
      mesh.triangles.push_back({a, c, d});
    }
  }
}

}  // namespace

Mesh make_demo_mesh(uint32_t target_faces) {
  target_faces = std::clamp<uint32_t>(target_faces, 384, 1u << 26);
  // Keep cells roughly square: the knot is about 11 times longer than the
  // tube's circumference.
  constexpr double kAspect = 11.0;
  uint32_t around = static_cast<uint32_t>(std::lround(std::sqrt(target_faces / (2 * kAspect))));
  around = std::max<uint32_t>(around, 8);
  const uint32_t along =
      std::max<uint32_t>(24, static_cast<uint32_t>(std::lround(target_faces / (2.0 * around))));

  Mesh mesh;
  mesh.positions.reserve(static_cast<size_t>(along) * around);
  for (uint32_t i = 0; i < along; ++i) {
    const double t = 2 * kPi * i / along;
    const Frame f = frame_at(t);
    for (uint32_t j = 0; j < around; ++j) {
      const double a = 2 * kPi * j / around;
      const Vec3d dir = f.normal * std::cos(a) + f.binormal * std::sin(a);
      const Vec3d rough = f.origin + dir * 0.16;
      mesh.positions.push_back(to_float(f.origin + dir * tube_radius(t, a, rough)));
    }
  }
  // Rows advance along the knot, columns around the tube; with the frame
  // (tangent, normal, binormal) right-handed this winding faces outwards.
  add_quad_grid_faces(mesh, along, around, true, true);
  for (Triangle& t : mesh.triangles) std::swap(t[1], t[2]);
  return mesh;
}

Mesh make_icosahedron() {
  const float p = static_cast<float>((1 + std::sqrt(5.0)) / 2);
  const float s = 1.0f / std::sqrt(1 + p * p);
  const float a = s, b = p * s;
  Mesh m;
  m.positions = {{-a, b, 0},  {a, b, 0},  {-a, -b, 0}, {a, -b, 0}, {0, -a, b},  {0, a, b},
                 {0, -a, -b}, {0, a, -b}, {b, 0, -a},  {b, 0, a},  {-b, 0, -a}, {-b, 0, a}};
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  return m;
}

Mesh make_icosphere(uint32_t subdivisions) {
  subdivisions = std::min<uint32_t>(subdivisions, 10);
  Mesh m = make_icosahedron();
  for (uint32_t level = 0; level < subdivisions; ++level) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoint;
    auto mid = [&](uint32_t a, uint32_t b) {
      const auto key = std::minmax(a, b);
      auto [it, inserted] = midpoint.emplace(key, m.vertex_count());
      if (inserted) {
        const Vec3d p = (to_double(m.positions[a]) + to_double(m.positions[b])) * 0.5;
        m.positions.push_back(to_float(normalized(p)));
      }
      return it->second;
    };
    std::vector<Triangle> next;
    next.reserve(m.triangles.size() * 4);
    for (const Triangle& t : m.triangles) {
      const uint32_t ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
      next.push_back({t[0], ab, ca});
      next.push_back({t[1], bc, ab});
      next.push_back({t[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    m.triangles.swap(next);
  }
  return m;
}

Mesh make_open_grid(uint32_t n) {
  n = std::max<uint32_t>(n, 1);
  Mesh m;
  for (uint32_t i = 0; i <= n; ++i) {
    for (uint32_t j = 0; j <= n; ++j) {
      const double x = static_cast<double>(j) / n, y = static_cast<double>(i) / n;
      const double z = 0.05 * std::sin(2 * kPi * x) * std::cos(2 * kPi * y);
      m.positions.push_back(to_float(Vec3d{x, y, z}));
    }
  }
  // Rows along y, columns along x: (a, b, c) = (i,j), (i+1,j), (i+1,j+1)
  // winds clockwise seen from +z; swap to face +z.
  add_quad_grid_faces(m, n + 1, n + 1, false, false);
  for (Triangle& t : m.triangles) std::swap(t[1], t[2]);
  return m;
}

Mesh make_multi_component(uint32_t count) {
  count = std::max<uint32_t>(count, 1);
  const Mesh sphere = make_icosphere(1);
  Mesh m;
  for (uint32_t k = 0; k < count; ++k) {
    const uint32_t offset = m.vertex_count();
    const float shift = 2.5f * static_cast<float>(k);
    for (const Vec3f& p : sphere.positions) m.positions.push_back({p.x + shift, p.y, p.z});
    for (const Triangle& t : sphere.triangles)
      m.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  }
  return m;
}

Mesh make_torus(uint32_t major, uint32_t minor) {
  major = std::max<uint32_t>(major, 3);
  minor = std::max<uint32_t>(minor, 3);
  Mesh m;
  for (uint32_t i = 0; i < major; ++i) {
    const double u = 2 * kPi * i / major;
    for (uint32_t j = 0; j < minor; ++j) {
      const double v = 2 * kPi * j / minor;
      const double r = 1.0 + 0.35 * std::cos(v);
      m.positions.push_back(to_float(Vec3d{r * std::cos(u), r * std::sin(u), 0.35 * std::sin(v)}));
    }
  }
  add_quad_grid_faces(m, major, minor, true, true);
  return m;
}

Mesh make_faceted_cube(uint32_t segments) {
  const uint32_t n = std::clamp<uint32_t>(segments, 1, 4096);
  Mesh m;
  // Grid points on the cube's surface, keyed by their integer coordinates in
  // [0, n]^3, so the faces share the points on the cube's edges.
  std::map<std::array<uint32_t, 3>, uint32_t> index_of;
  auto vertex = [&](std::array<uint32_t, 3> g) {
    auto [it, added] = index_of.try_emplace(g, m.vertex_count());
    if (added) {
      const Vec3d p{2.0 * g[0] / n - 1.0, 2.0 * g[1] / n - 1.0, 2.0 * g[2] / n - 1.0};
      m.positions.push_back(to_float(p));
      m.colors.push_back({static_cast<float>(g[0]) / n, static_cast<float>(g[1]) / n,
                          static_cast<float>(g[2]) / n, 1.0f});
    }
    return it->second;
  };
  // Each face: the axis it faces along, its sign, and two in-plane axes
  // (u, v) with u x v pointing outwards.
  struct Side {
    int axis, u, v;
    bool positive;
  };
  const Side sides[6] = {{0, 1, 2, true},  {0, 2, 1, false}, {1, 2, 0, true},
                         {1, 0, 2, false}, {2, 0, 1, true},  {2, 1, 0, false}};
  for (uint32_t side_index = 0; side_index < 6; ++side_index) {
    const Side& side = sides[side_index];
    Vec3f normal{0, 0, 0};
    (&normal.x)[side.axis] = side.positive ? 1.0f : -1.0f;
    const uint32_t value_base = static_cast<uint32_t>(m.corner_texcoords.values.size());
    std::vector<uint32_t> grid((n + 1) * (n + 1));
    for (uint32_t j = 0; j <= n; ++j) {
      for (uint32_t i = 0; i <= n; ++i) {
        std::array<uint32_t, 3> g{};
        g[side.axis] = side.positive ? n : 0;
        g[side.u] = i;
        g[side.v] = j;
        grid[j * (n + 1) + i] = vertex(g);
        // Face `side_index` in cell (side_index % 3, side_index / 3) of a
        // 3 x 2 atlas, inset so no two faces share a value.
        const double cell_u = side_index % 3, cell_v = side_index / 3;
        m.corner_texcoords.values.push_back(
            {static_cast<float>((cell_u + 0.05 + 0.9 * i / n) / 3),
             static_cast<float>((cell_v + 0.05 + 0.9 * j / n) / 2)});
        m.corner_normals.values.push_back(normal);
      }
    }
    for (uint32_t j = 0; j < n; ++j) {
      for (uint32_t i = 0; i < n; ++i) {
        const uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
        for (const std::array<uint32_t, 3>& t :
             {std::array<uint32_t, 3>{a, b, d}, std::array<uint32_t, 3>{a, d, c}}) {
          m.triangles.push_back({grid[t[0]], grid[t[1]], grid[t[2]]});
          for (uint32_t k : t) {
            m.corner_texcoords.corners.push_back(value_base + k);
            m.corner_normals.corners.push_back(value_base + k);
          }
        }
      }
    }
  }
  return m;
}

Mesh make_uv_sphere(uint32_t segments, uint32_t rings) {
  const uint32_t s = std::clamp<uint32_t>(segments, 3, 1u << 14);
  const uint32_t r = std::clamp<uint32_t>(rings, 2, 1u << 14);
  Mesh m;
  auto point = [](double longitude, double latitude) {
    return to_float(Vec3d{std::sin(latitude) * std::cos(longitude),
                          std::sin(latitude) * std::sin(longitude), std::cos(latitude)});
  };
  // Vertices: north pole, rings 1..r-1 of s vertices each, south pole.
  m.positions.push_back({0, 0, 1});
  for (uint32_t k = 1; k < r; ++k) {
    for (uint32_t i = 0; i < s; ++i) m.positions.push_back(point(2 * kPi * i / s, kPi * k / r));
  }
  m.positions.push_back({0, 0, -1});
  m.normals = m.positions;
  const uint32_t south = m.vertex_count() - 1;
  auto ring_vertex = [s](uint32_t k, uint32_t i) { return 1 + (k - 1) * s + i % s; };

  // Texture coordinates: a (s + 1) x (r + 1) grid (column s repeats column
  // 0's vertices with u = 1: the seam); the poles use the row's values at
  // the middle of each segment.
  CornerAttribute<Vec2f>& uv = m.corner_texcoords;
  auto uv_value = [&](double u, double v) {
    uv.values.push_back({static_cast<float>(u), static_cast<float>(v)});
    return static_cast<uint32_t>(uv.values.size() - 1);
  };
  std::vector<uint32_t> grid_value((s + 1) * (r + 1), kNoValue);
  auto grid_uv = [&](uint32_t k, uint32_t i) {
    uint32_t& value = grid_value[k * (s + 1) + i];
    if (value == kNoValue) value = uv_value(static_cast<double>(i) / s, static_cast<double>(k) / r);
    return value;
  };
  auto face = [&](std::array<uint32_t, 3> v, std::array<uint32_t, 3> t) {
    m.triangles.push_back(v);
    uv.corners.insert(uv.corners.end(), t.begin(), t.end());
  };
  for (uint32_t i = 0; i < s; ++i) {
    const uint32_t pole = uv_value((i + 0.5) / s, 0.0);
    face({0, ring_vertex(1, i), ring_vertex(1, i + 1)}, {pole, grid_uv(1, i), grid_uv(1, i + 1)});
  }
  for (uint32_t k = 1; k + 1 < r; ++k) {
    for (uint32_t i = 0; i < s; ++i) {
      const uint32_t a = ring_vertex(k, i), b = ring_vertex(k, i + 1);
      const uint32_t c = ring_vertex(k + 1, i), d = ring_vertex(k + 1, i + 1);
      face({a, c, d}, {grid_uv(k, i), grid_uv(k + 1, i), grid_uv(k + 1, i + 1)});
      face({a, d, b}, {grid_uv(k, i), grid_uv(k + 1, i + 1), grid_uv(k, i + 1)});
    }
  }
  for (uint32_t i = 0; i < s; ++i) {
    const uint32_t pole = uv_value((i + 0.5) / s, 1.0);
    face({south, ring_vertex(r - 1, i + 1), ring_vertex(r - 1, i)},
         {pole, grid_uv(r - 1, i + 1), grid_uv(r - 1, i)});
  }
  return m;
}

}  // namespace meshstream
