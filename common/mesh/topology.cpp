#include "common/mesh/topology.h"

#include <algorithm>
#include <array>
#include <vector>

#include "common/mesh/edge_groups.h"
#include "common/mesh/same_faces.h"
#include "common/mesh/union_find.h"

namespace meshstream {
namespace {

bool usable(const Triangle& t, uint32_t n) {
  return t[0] < n && t[1] < n && t[2] < n && t[0] != t[1] && t[1] != t[2] && t[2] != t[0];
}

uint32_t count_duplicates(const Mesh& mesh) {
  const std::vector<uint32_t> first = first_face_with_same_vertices(mesh);
  uint32_t dups = 0;
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    dups += usable(mesh.triangles[f], mesh.vertex_count()) && first[f] != f;
  }
  return dups;
}

}  // namespace

MeshStats compute_stats(const Mesh& mesh) {
  MeshStats s;
  const uint32_t n = mesh.vertex_count();
  s.vertices = n;
  s.faces = mesh.face_count();
  s.bbox = bounding_box(mesh);

  std::vector<uint8_t> referenced(n, 0);
  UnionFind vertex_sets(n);
  uint32_t valid_faces = 0;
  for (const Triangle& t : mesh.triangles) {
    if (!usable(t, n)) {
      ++s.invalid_faces;
      continue;
    }
    ++valid_faces;
    for (uint32_t v : t) referenced[v] = 1;
    vertex_sets.unite(t[0], t[1]);
    vertex_sets.unite(t[1], t[2]);
  }
  for (uint32_t v = 0; v < n; ++v) {
    if (!referenced[v]) continue;
    ++s.referenced_vertices;
    if (vertex_sets.find(v) == v) ++s.components;
  }
  s.isolated_vertices = n - s.referenced_vertices;
  s.duplicate_faces = count_duplicates(mesh);

  // Edges, boundary loops; the rest from count_nonmanifold.
  const EdgeGroups groups = build_edge_groups(mesh);
  s.edges = groups.edge_count();
  UnionFind boundary_sets(n);
  std::vector<uint8_t> on_boundary(n, 0);
  for (uint32_t e = 0; e < groups.edge_count(); ++e) {
    if (groups.use_count(e) != 1) continue;
    ++s.boundary_edges;
    boundary_sets.unite(groups.lo[e], groups.hi[e]);
    on_boundary[groups.lo[e]] = on_boundary[groups.hi[e]] = 1;
  }
  for (uint32_t v = 0; v < n; ++v) {
    if (on_boundary[v] && boundary_sets.find(v) == v) ++s.boundary_loops;
  }
  const ManifoldCounts counts = count_nonmanifold(mesh, groups);
  s.nonmanifold_edges = counts.nonmanifold_edges;
  s.nonmanifold_vertices = counts.nonmanifold_vertices;
  s.orientation_conflicts = counts.orientation_conflicts;

  s.euler = static_cast<int64_t>(s.referenced_vertices) - s.edges + valid_faces;
  s.manifold = counts.manifold();
  s.genus_valid = s.manifold && s.orientation_conflicts == 0;
  s.genus = (2 * static_cast<int64_t>(s.components) - s.euler - s.boundary_loops) / 2;
  return s;
}

namespace {

uint32_t corner_at(const Mesh& mesh, uint32_t f, uint32_t v) {
  const Triangle& t = mesh.triangles[f];
  return 3 * f + (t[0] == v ? 0 : (t[1] == v ? 1 : 2));
}

}  // namespace

UnionFind two_face_fans(const Mesh& mesh, const EdgeGroups& groups) {
  UnionFind sets(3 * mesh.face_count());
  for (uint32_t e = 0; e < groups.edge_count(); ++e) {
    if (groups.use_count(e) != 2) continue;
    const uint32_t fa = groups.uses[groups.begin[e]].face;
    const uint32_t fb = groups.uses[groups.begin[e] + 1].face;
    sets.unite(corner_at(mesh, fa, groups.lo[e]), corner_at(mesh, fb, groups.lo[e]));
    sets.unite(corner_at(mesh, fa, groups.hi[e]), corner_at(mesh, fb, groups.hi[e]));
  }
  return sets;
}

ManifoldCounts count_nonmanifold(const Mesh& mesh, const EdgeGroups& groups) {
  UnionFind fans = two_face_fans(mesh, groups);
  return count_nonmanifold(mesh, groups, fans);
}

ManifoldCounts count_nonmanifold(const Mesh& mesh, const EdgeGroups& groups, UnionFind& fans) {
  ManifoldCounts s;
  const uint32_t n = mesh.vertex_count();
  const uint32_t faces = mesh.face_count();
  // Fans join, at each endpoint, the corners of all faces that share an
  // edge. `fans` has the two-face edges; the faces of each edge with more
  // than two are joined here, over the fans they are in (few: a small
  // union-find over those fans, found by binary search).
  std::vector<uint8_t> at_crowded_edge(n, 0);
  std::vector<std::pair<uint32_t, uint32_t>> extra;  // fans to join
  for (uint32_t e = 0; e < groups.edge_count(); ++e) {
    const uint32_t count = groups.use_count(e);
    const EdgeUse* uses = &groups.uses[groups.begin[e]];
    if (count == 2 && uses[0].forward == uses[1].forward) ++s.orientation_conflicts;
    if (count <= 2) continue;
    ++s.nonmanifold_edges;
    at_crowded_edge[groups.lo[e]] = at_crowded_edge[groups.hi[e]] = 1;
    for (uint32_t k = 1; k < count; ++k) {
      for (const uint32_t v : {groups.lo[e], groups.hi[e]}) {
        extra.emplace_back(fans.find(corner_at(mesh, uses[0].face, v)),
                           fans.find(corner_at(mesh, uses[k].face, v)));
      }
    }
  }
  std::vector<uint32_t> joined_fans;
  joined_fans.reserve(2 * extra.size());
  for (const auto& [a, b] : extra) {
    joined_fans.push_back(a);
    joined_fans.push_back(b);
  }
  std::sort(joined_fans.begin(), joined_fans.end());
  joined_fans.erase(std::unique(joined_fans.begin(), joined_fans.end()), joined_fans.end());
  auto index_of = [&joined_fans](uint32_t root) {
    return static_cast<uint32_t>(std::lower_bound(joined_fans.begin(), joined_fans.end(), root) -
                                 joined_fans.begin());
  };
  UnionFind joined(static_cast<uint32_t>(joined_fans.size()));
  for (const auto& [a, b] : extra) joined.unite(index_of(a), index_of(b));
  extra = {};

  // A vertex is non-manifold when its corners fall into more than one set.
  std::vector<uint32_t> first_fan(n, 0xFFFFFFFFu);
  std::vector<uint8_t> counted(n, 0);
  for (uint32_t f = 0; f < faces; ++f) {
    const Triangle& t = mesh.triangles[f];
    if (!usable(t, n)) continue;
    for (uint32_t i = 0; i < 3; ++i) {
      uint32_t root = fans.find(3 * f + i);
      const uint32_t v = t[i];
      if (at_crowded_edge[v]) {
        const uint32_t k = index_of(root);
        if (k < joined_fans.size() && joined_fans[k] == root) root = joined_fans[joined.find(k)];
      }
      if (first_fan[v] == 0xFFFFFFFFu) {
        first_fan[v] = root;
      } else if (first_fan[v] != root && !counted[v]) {
        counted[v] = 1;
        ++s.nonmanifold_vertices;
      }
    }
  }
  return s;
}

}  // namespace meshstream
