#include "common/mesh/manifold_repair.h"

#include <algorithm>
#include <deque>
#include <sstream>

#include "common/mesh/adjacency.h"
#include "common/mesh/edge_groups.h"
#include "common/mesh/union_find.h"

namespace meshstream {
namespace {

std::string where(const Mesh& mesh, uint32_t v) {
  const Vec3f& p = mesh.positions[v];
  std::ostringstream s;
  s << "vertex " << v << " at (" << p.x << ", " << p.y << ", " << p.z << ")";
  return s.str();
}

std::string edge_name(const Mesh& mesh, uint32_t a, uint32_t b) {
  return "edge between " + where(mesh, a) + " and " + where(mesh, b);
}

uint32_t corner_at(const Mesh& mesh, uint32_t f, uint32_t v) {
  const Triangle& t = mesh.triangles[f];
  return 3 * f + (t[0] == v ? 0 : (t[1] == v ? 1 : 2));
}

// Union-find over corners: two corners are in one set when their faces share
// an edge with exactly two faces at that corner's vertex.
UnionFind fans_through_manifold_edges(const Mesh& mesh, const EdgeGroups& groups) {
  UnionFind sets(3 * mesh.face_count());
  for (uint32_t e = 0; e < groups.edge_count(); ++e) {
    if (groups.use_count(e) != 2) continue;
    const EdgeUse& a = groups.uses[groups.begin[e]];
    const EdgeUse& b = groups.uses[groups.begin[e] + 1];
    sets.unite(corner_at(mesh, a.face, groups.lo[e]), corner_at(mesh, b.face, groups.lo[e]));
    sets.unite(corner_at(mesh, a.face, groups.hi[e]), corner_at(mesh, b.face, groups.hi[e]));
  }
  return sets;
}

template <class T>
void copy_attribute(std::vector<T>& values, uint32_t v) {
  if (!values.empty()) values.push_back(values[v]);
}

uint32_t add_copy(Mesh& mesh, uint32_t v) {
  mesh.positions.push_back(mesh.positions[v]);
  copy_attribute(mesh.normals, v);
  copy_attribute(mesh.colors, v);
  copy_attribute(mesh.texcoords, v);
  return mesh.vertex_count() - 1;
}

// Step 1. Returns the number of flipped faces.
Result<uint32_t> orient(Mesh& mesh, const EdgeGroups& groups) {
  const uint32_t f_count = mesh.face_count();
  // Links between faces across two-face edges, as CSR; `same` = the two faces
  // walk the edge in the same direction (one of them must flip).
  std::vector<uint32_t> offset(f_count + 1, 0);
  for (uint32_t e = 0; e < groups.edge_count(); ++e) {
    if (groups.use_count(e) != 2) continue;
    ++offset[groups.uses[groups.begin[e]].face + 1];
    ++offset[groups.uses[groups.begin[e] + 1].face + 1];
  }
  for (uint32_t f = 0; f < f_count; ++f) offset[f + 1] += offset[f];
  struct Link {
    uint32_t face;
    bool same;
  };
  std::vector<Link> links(offset[f_count]);
  std::vector<uint32_t> fill(offset.begin(), offset.end() - 1);
  for (uint32_t e = 0; e < groups.edge_count(); ++e) {
    if (groups.use_count(e) != 2) continue;
    const EdgeUse& a = groups.uses[groups.begin[e]];
    const EdgeUse& b = groups.uses[groups.begin[e] + 1];
    const bool same = a.forward == b.forward;
    links[fill[a.face]++] = {b.face, same};
    links[fill[b.face]++] = {a.face, same};
  }

  std::vector<int8_t> flip(f_count, -1);
  std::vector<uint32_t> component;
  std::deque<uint32_t> queue;
  uint32_t flipped_total = 0;
  for (uint32_t start = 0; start < f_count; ++start) {
    if (flip[start] >= 0) continue;
    component.clear();
    flip[start] = 0;
    queue.push_back(start);
    uint32_t flipped = 0;
    while (!queue.empty()) {
      const uint32_t f = queue.front();
      queue.pop_front();
      component.push_back(f);
      for (uint32_t k = offset[f]; k < offset[f + 1]; ++k) {
        const Link& link = links[k];
        const int8_t want = static_cast<int8_t>(flip[f] ^ (link.same ? 1 : 0));
        if (flip[link.face] < 0) {
          flip[link.face] = want;
          flipped += want;
          queue.push_back(link.face);
        } else if (flip[link.face] != want) {
          const Triangle& t = mesh.triangles[f];
          return make_error(ErrorCode::kNonManifold,
                            "the surface containing face " + std::to_string(f) + " (" +
                                where(mesh, t[0]) +
                                ", ...) cannot be oriented consistently (non-orientable, like a "
                                "Moebius strip)");
        }
      }
    }
    // Keep the majority's orientation: flip the fewest faces.
    const bool invert = 2 * flipped > component.size();
    for (uint32_t f : component) {
      const bool do_flip = (flip[f] == 1) != invert;
      if (do_flip) {
        std::swap(mesh.triangles[f][1], mesh.triangles[f][2]);
        ++flipped_total;
      }
    }
  }
  return flipped_total;
}

// Step 2. Returns the number of vertex copies made.
uint32_t split_fans(Mesh& mesh, const EdgeGroups& groups) {
  UnionFind sets = fans_through_manifold_edges(mesh, groups);
  const uint32_t corner_count = 3 * mesh.face_count();
  std::vector<uint32_t> owner(mesh.vertex_count(), kNone);  // root keeping the original
  std::vector<uint32_t> root_vertex(corner_count, kNone);
  uint32_t copies = 0;
  for (uint32_t c = 0; c < corner_count; ++c) {
    const uint32_t v = mesh.triangles[c / 3][c % 3];
    const uint32_t root = sets.find(c);
    if (root_vertex[root] == kNone) {
      if (owner[v] == kNone) {
        owner[v] = root;
        root_vertex[root] = v;
      } else {
        root_vertex[root] = add_copy(mesh, v);
        ++copies;
      }
    }
    mesh.triangles[c / 3][c % 3] = root_vertex[root];
  }
  return copies;
}

// Step 3. Returns {faces detached, vertex copies made}.
std::pair<uint32_t, uint32_t> detach_extra_faces(Mesh& mesh, const EdgeGroups& groups) {
  std::vector<uint8_t> detach(mesh.face_count(), 0);
  bool any = false;
  for (uint32_t e = 0; e < groups.edge_count(); ++e) {
    const uint32_t count = groups.use_count(e);
    if (count <= 2) continue;
    const EdgeUse* uses = &groups.uses[groups.begin[e]];
    uint32_t keep_a = 0, keep_b = kNone;
    for (uint32_t i = 0; i < count && keep_b == kNone; ++i) {
      for (uint32_t j = i + 1; j < count; ++j) {
        if (uses[i].forward != uses[j].forward) {
          keep_a = i;
          keep_b = j;
          break;
        }
      }
    }
    for (uint32_t i = 0; i < count; ++i) {
      if (i != keep_a && i != keep_b) {
        detach[uses[i].face] = 1;
        any = true;
      }
    }
  }
  if (!any) return {0, 0};
  std::vector<uint32_t> users(mesh.vertex_count(), 0);
  for (const Triangle& t : mesh.triangles) {
    for (uint32_t v : t) ++users[v];
  }
  uint32_t faces = 0, copies = 0;
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    if (!detach[f]) continue;
    ++faces;
    for (uint32_t& v : mesh.triangles[f]) {
      if (users[v] <= 1) continue;  // already only this face's
      --users[v];
      v = add_copy(mesh, v);
      users.push_back(1);
      ++copies;
    }
  }
  return {faces, copies};
}

}  // namespace

Status check_manifold(const Mesh& mesh) {
  const EdgeGroups groups = build_edge_groups(mesh);
  for (uint32_t e = 0; e < groups.edge_count(); ++e) {
    const uint32_t count = groups.use_count(e);
    const EdgeUse* uses = &groups.uses[groups.begin[e]];
    if (count > 2) {
      return make_error(ErrorCode::kNonManifold,
                        "non-manifold edge: the " + edge_name(mesh, groups.lo[e], groups.hi[e]) +
                            " has " + std::to_string(count) + " faces (at most 2 allowed)");
    }
    if (count == 2 && uses[0].forward == uses[1].forward) {
      return make_error(ErrorCode::kNonManifold,
                        "inconsistent orientation: faces " + std::to_string(uses[0].face) + " and " +
                            std::to_string(uses[1].face) + " walk the " +
                            edge_name(mesh, groups.lo[e], groups.hi[e]) + " in the same direction");
    }
  }
  UnionFind sets = fans_through_manifold_edges(mesh, groups);
  std::vector<uint32_t> first_root(mesh.vertex_count(), kNone);
  for (uint32_t c = 0; c < 3 * mesh.face_count(); ++c) {
    const uint32_t v = mesh.triangles[c / 3][c % 3];
    const uint32_t root = sets.find(c);
    if (first_root[v] == kNone) {
      first_root[v] = root;
    } else if (first_root[v] != root) {
      return make_error(ErrorCode::kNonManifold,
                        "non-manifold vertex: " + where(mesh, v) +
                            " joins several separate fans of faces");
    }
  }
  return {};
}

Result<RepairCounts> make_manifold(Mesh& mesh) {
  RepairCounts counts;
  constexpr int kMaxRounds = 32;
  for (int round = 0; round < kMaxRounds; ++round) {
    EdgeGroups groups = build_edge_groups(mesh);
    auto flipped = orient(mesh, groups);
    if (!flipped) return tl::unexpected(flipped.error());
    counts.flipped_faces += *flipped;
    if (*flipped > 0) groups = build_edge_groups(mesh);
    const uint32_t split = split_fans(mesh, groups);
    counts.split_vertices += split;
    if (split > 0) groups = build_edge_groups(mesh);
    const auto [detached, copies] = detach_extra_faces(mesh, groups);
    counts.detached_faces += detached;
    counts.split_vertices += copies;
    if (*flipped == 0 && split == 0 && detached == 0) break;
  }
  if (auto adjacency = Adjacency::build(mesh); !adjacency) {
    return make_error(ErrorCode::kNonManifold,
                      "non-manifold repair did not converge: " + adjacency.error().message);
  }
  return counts;
}

}  // namespace meshstream
