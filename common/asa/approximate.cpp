#include "common/asa/approximate.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace meshstream {
namespace {

struct EdgeFace {
  uint32_t a, b, face;  // a < b
};

// Per vertex: its distinct neighbours (CSR) and whether it must stay fixed
// (boundary, sharp or non-manifold edge).
struct Neighbourhood {
  std::vector<uint32_t> start, neighbours;
  std::vector<uint8_t> fixed;
};

Neighbourhood neighbourhood(const Mesh& mesh, float sharp_cos) {
  const uint32_t n = mesh.vertex_count();
  std::vector<EdgeFace> edges;
  edges.reserve(3 * size_t(mesh.face_count()));
  std::vector<Vec3f> unit(mesh.face_count());
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    unit[f] = face_normal(mesh, f);
    const Triangle& t = mesh.triangles[f];
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[k], b = t[(k + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b), f});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const EdgeFace& x, const EdgeFace& y) {
    return x.a != y.a ? x.a < y.a : (x.b != y.b ? x.b < y.b : x.face < y.face);
  });
  Neighbourhood nb;
  nb.fixed.assign(n, 0);
  std::vector<std::pair<uint32_t, uint32_t>> unique_edges;
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].a == edges[i].a && edges[j].b == edges[i].b) ++j;
    const bool keep_fixed =
        j - i != 2 || dot(unit[edges[i].face], unit[edges[i + 1].face]) < sharp_cos;
    if (keep_fixed) nb.fixed[edges[i].a] = nb.fixed[edges[i].b] = 1;
    unique_edges.push_back({edges[i].a, edges[i].b});
    i = j;
  }
  nb.start.assign(n + 1, 0);
  for (const auto& [a, b] : unique_edges) {
    ++nb.start[a + 1];
    ++nb.start[b + 1];
  }
  for (uint32_t v = 0; v < n; ++v) nb.start[v + 1] += nb.start[v];
  std::vector<uint32_t> fill(nb.start.begin(), nb.start.end() - 1);
  nb.neighbours.resize(nb.start.back());
  for (const auto& [a, b] : unique_edges) {
    nb.neighbours[fill[a]++] = b;
    nb.neighbours[fill[b]++] = a;
  }
  return nb;
}

// One Jacobi step: every free vertex moves by `factor` times the normal
// part of its umbrella Laplacian.
void step(Mesh& mesh, const Neighbourhood& nb, float factor) {
  const std::vector<Vec3f> normals = compute_vertex_normals(mesh);
  std::vector<Vec3f> moved = mesh.positions;
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    const uint32_t count = nb.start[v + 1] - nb.start[v];
    if (nb.fixed[v] || count == 0) continue;
    Vec3d mean{};
    for (uint32_t i = nb.start[v]; i < nb.start[v + 1]; ++i) {
      const Vec3f& q = mesh.positions[nb.neighbours[i]];
      mean = mean + Vec3d{q.x, q.y, q.z};
    }
    const Vec3f& p = mesh.positions[v];
    const Vec3d laplacian = mean / double(count) - Vec3d{p.x, p.y, p.z};
    const Vec3d nrm{normals[v].x, normals[v].y, normals[v].z};
    const double along = double(factor) * dot(laplacian, nrm);
    moved[v] =
        Vec3f{float(p.x + along * nrm.x), float(p.y + along * nrm.y), float(p.z + along * nrm.z)};
  }
  mesh.positions = std::move(moved);
}

}  // namespace

Status relax_toward_smooth(Mesh& mesh, const RelaxOptions& o) {
  if (o.iterations < 0 || o.iterations > 100 || !(o.lambda > 0 && o.lambda < 1) ||
      !(o.mu < 0 && -o.mu < 1 && -o.mu >= o.lambda) ||
      !(o.sharp_degrees > 0 && o.sharp_degrees <= 180))
    return make_error(ErrorCode::kInvalidArgument,
                      "relax: need 0 <= iterations <= 100, 0 < lambda < 1, lambda <= -mu < 1 "
                      "and 0 < sharp angle <= 180 degrees");
  if (auto s = validate_arrays(mesh); !s) return s;
  if (o.iterations == 0 || mesh.triangles.empty()) return {};
  const float sharp_cos = o.sharp_degrees >= 180
                              ? -2.0f
                              : float(std::cos(double(o.sharp_degrees) * std::numbers::pi / 180));
  const Neighbourhood nb = neighbourhood(mesh, sharp_cos);
  for (int i = 0; i < o.iterations; ++i) {
    step(mesh, nb, o.lambda);
    step(mesh, nb, o.mu);
  }
  return {};
}

}  // namespace meshstream
