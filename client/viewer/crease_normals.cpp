#include "client/viewer/crease_normals.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace meshstream::client {
namespace {

// Union-find over the corners around one vertex (a handful of entries).
uint32_t find_root(std::vector<uint32_t>& parent, uint32_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

// Fans up to this size compare all pairs (cheaper than sorting them).
constexpr uint32_t kSmallFan = 16;

}  // namespace

ShadingMesh split_normals_at_creases(const Mesh& mesh, float crease_degrees) {
  const uint32_t V = mesh.vertex_count();
  const uint32_t F = mesh.face_count();
  ShadingMesh out;
  out.positions = mesh.positions;
  out.triangles = mesh.triangles;
  out.normals.assign(V, Vec3f{});

  // Area-weighted (|cross| = 2 * area) and unit face normals, computed in
  // double, kept in float (half the memory traffic; shading needs no more).
  std::vector<Vec3f> weighted(F);
  std::vector<Vec3f> unit(F);
  for (uint32_t f = 0; f < F; ++f) {
    const Triangle& t = mesh.triangles[f];
    Vec3d a = to_double(mesh.positions[t[0]]);
    Vec3d n = cross(to_double(mesh.positions[t[1]]) - a, to_double(mesh.positions[t[2]]) - a);
    weighted[f] = to_float(n);
    unit[f] = to_float(normalized(n));
  }
  const bool never_split = crease_degrees >= 180.0f;
  const float cos_limit = static_cast<float>(std::cos(crease_degrees * M_PI / 180.0));
  // A face with no area has no direction: it neither joins nor separates
  // groups (it could otherwise bridge a crease), and draws nothing.
  auto has_area = [&](uint32_t f) { return squared_length(unit[f]) > 0; };
  auto smooth_between = [&](uint32_t f, uint32_t g) {
    if (!has_area(f) || !has_area(g)) return false;
    return never_split || dot(unit[f], unit[g]) >= cos_limit;
  };

  // Corners (3 f + k) grouped by vertex: CSR offsets.
  std::vector<uint32_t> start(V + 1, 0);
  for (const Triangle& t : mesh.triangles)
    for (uint32_t v : t) ++start[v + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<uint32_t> corners(static_cast<size_t>(F) * 3);
  {
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (uint32_t f = 0; f < F; ++f)
      for (uint32_t k = 0; k < 3; ++k) corners[fill[mesh.triangles[f][k]]++] = 3 * f + k;
  }

  const bool has_normals = mesh.normals.size() == mesh.positions.size();
  std::vector<uint32_t> parent, group_of;
  std::vector<std::pair<uint32_t, uint32_t>> edges;  // (other vertex, local corner)
  std::vector<Vec3d> group_sum;
  for (uint32_t v = 0; v < V; ++v) {
    const uint32_t begin = start[v], count = start[v + 1] - begin;
    if (count == 0) {
      if (has_normals) out.normals[v] = mesh.normals[v];
      continue;
    }
    // Faces around v that share an edge (v, w) are neighbours in the fan.
    parent.resize(count);
    std::iota(parent.begin(), parent.end(), 0u);
    auto join_if_smooth = [&](uint32_t i, uint32_t j) {
      if (!smooth_between(corners[begin + i] / 3, corners[begin + j] / 3)) return;
      parent[find_root(parent, i)] = find_root(parent, j);
    };
    if (count <= kSmallFan) {
      // A usual fan (valence about 6): compare every pair of corners.
      uint32_t next[kSmallFan], prev[kSmallFan];
      for (uint32_t i = 0; i < count; ++i) {
        const uint32_t c = corners[begin + i];
        const Triangle& t = mesh.triangles[c / 3];
        next[i] = t[(c % 3 + 1) % 3];
        prev[i] = t[(c % 3 + 2) % 3];
      }
      for (uint32_t i = 0; i < count; ++i) {
        for (uint32_t j = i + 1; j < count; ++j) {
          if (next[i] == next[j] || next[i] == prev[j] || prev[i] == next[j] ||
              prev[i] == prev[j]) {
            join_if_smooth(i, j);
          }
        }
      }
    } else {
      // A large fan: sort the two edges of every corner by their other end
      // and compare the corners within each run of equal ends.
      edges.clear();
      for (uint32_t i = 0; i < count; ++i) {
        const uint32_t c = corners[begin + i];
        const Triangle& t = mesh.triangles[c / 3];
        edges.push_back({t[(c % 3 + 1) % 3], i});
        edges.push_back({t[(c % 3 + 2) % 3], i});
      }
      std::sort(edges.begin(), edges.end());
      for (size_t run = 0, end = 0; run < edges.size(); run = end) {
        end = run + 1;
        while (end < edges.size() && edges[end].first == edges[run].first) ++end;
        // Usually two faces; more on a non-manifold edge: every pair.
        for (size_t a = run; a < end; ++a)
          for (size_t b = a + 1; b < end; ++b) join_if_smooth(edges[a].second, edges[b].second);
      }
    }
    // Number the groups of faces with area in corner order; the first keeps
    // index v, and faces without area take it too (no copy for them).
    group_of.assign(count, UINT32_MAX);
    group_sum.assign(1, Vec3d{});
    uint32_t groups = 0;
    for (uint32_t i = 0; i < count; ++i) {
      const uint32_t f = corners[begin + i] / 3;
      if (!has_area(f)) continue;
      const uint32_t root = find_root(parent, i);
      if (group_of[root] == UINT32_MAX) {
        group_of[root] = groups++;
        if (groups > group_sum.size()) group_sum.push_back(Vec3d{});
      }
      group_sum[group_of[root]] += to_double(weighted[f]);
    }
    groups = std::max(groups, 1u);
    if (groups == 1) {
      out.normals[v] = has_normals ? mesh.normals[v] : to_float(normalized(group_sum[0]));
      continue;
    }
    const uint32_t first_copy = static_cast<uint32_t>(out.positions.size());
    out.normals[v] = to_float(normalized(group_sum[0]));
    for (uint32_t g = 1; g < groups; ++g) {
      out.positions.push_back(mesh.positions[v]);
      out.normals.push_back(to_float(normalized(group_sum[g])));
      out.copied_from.push_back(v);
    }
    for (uint32_t i = 0; i < count; ++i) {
      const uint32_t c = corners[begin + i];
      if (!has_area(c / 3)) continue;
      const uint32_t g = group_of[find_root(parent, i)];
      if (g == 0) continue;
      out.triangles[c / 3][c % 3] = first_copy + g - 1;
    }
  }
  return out;
}

}  // namespace meshstream::client
