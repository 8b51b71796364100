#include "common/mesh/manifold_repair.h"

#include <algorithm>
#include <deque>
#include <sstream>
#include <unordered_map>

#include "common/mesh/adjacency.h"
#include "common/mesh/corner_data.h"
#include "common/mesh/edge_groups.h"
#include "common/mesh/topology.h"
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

// Two faces kept connected across edge `edge`: uses[a] and uses[b] (indices
// into EdgeGroups::uses). Both faces of a two-face edge are always joined
// (required); those joins are read from the groups in edge order, never
// stored (that would be 16 bytes per edge of the mesh). The Join list holds
// only the pairings at non-manifold edges: a choice that orientation may
// overrule (cut).
struct Join {
  uint32_t edge;
  uint32_t a, b;
  bool cut = false;
};

// Joins the corners of uses a and b of `edge` at both of its endpoints.
void join_across(const Mesh& mesh, const EdgeGroups& groups, uint32_t edge, uint32_t a, uint32_t b,
                 UnionFind& sets) {
  const uint32_t fa = groups.uses[a].face, fb = groups.uses[b].face;
  sets.unite(corner_at(mesh, fa, groups.lo[edge]), corner_at(mesh, fb, groups.lo[edge]));
  sets.unite(corner_at(mesh, fa, groups.hi[edge]), corner_at(mesh, fb, groups.hi[edge]));
}

// Adds the given joins (not cut) to corner sets.
void add_joins(const Mesh& mesh, const EdgeGroups& groups, const std::vector<Join>& joins,
               UnionFind& sets) {
  for (const Join& j : joins) {
    if (!j.cut) join_across(mesh, groups, j.edge, j.a, j.b, sets);
  }
}

// Step 1 for one non-manifold edge: a greedy matching of consistently
// oriented pairs (opposite directions), best score first. Score: faces
// already in one fan at both endpoints (through two-face edges) beat faces
// in one fan at one endpoint beat the rest; ties go to agreeing normals.
void match_nonmanifold_edge(const Mesh& mesh, const EdgeGroups& groups, uint32_t e, UnionFind& fans,
                            std::vector<Join>& joins) {
  const uint32_t first = groups.begin[e], count = groups.use_count(e);
  struct Candidate {
    float score;
    uint32_t a, b;
  };
  std::vector<Candidate> candidates;
  for (uint32_t i = 0; i < count; ++i) {
    const EdgeUse& u = groups.uses[first + i];
    const Vec3f nu = face_normal(mesh, u.face);
    for (uint32_t k = i + 1; k < count; ++k) {
      const EdgeUse& w = groups.uses[first + k];
      if (u.forward == w.forward) continue;
      const bool at_lo = fans.find(corner_at(mesh, u.face, groups.lo[e])) ==
                         fans.find(corner_at(mesh, w.face, groups.lo[e]));
      const bool at_hi = fans.find(corner_at(mesh, u.face, groups.hi[e])) ==
                         fans.find(corner_at(mesh, w.face, groups.hi[e]));
      const float score = 4.0f * (at_lo + at_hi) + dot(nu, face_normal(mesh, w.face));
      candidates.push_back({score, first + i, first + k});
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& x, const Candidate& y) { return x.score > y.score; });
  std::vector<uint32_t> taken;
  for (const Candidate& c : candidates) {
    if (std::find(taken.begin(), taken.end(), c.a) != taken.end() ||
        std::find(taken.begin(), taken.end(), c.b) != taken.end()) {
      continue;
    }
    taken.push_back(c.a);
    taken.push_back(c.b);
    joins.push_back({e, c.a, c.b});
  }
}

// The pairings at non-manifold edges (the two-face edges are joined anyway).
// `fans`: the corner sets through the two-face edges alone (two_face_fans,
// with no joins); the matching reads them and leaves them as they are.
std::vector<Join> choose_joins(const Mesh& mesh, const EdgeGroups& groups, UnionFind& fans) {
  std::vector<Join> joins;
  for (uint32_t e = 0; e < groups.edge_count(); ++e) {
    if (groups.use_count(e) > 2) match_nonmanifold_edge(mesh, groups, e, fans, joins);
  }
  return joins;
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

// Disjoint sets that also track the parity (flip or not) of each element
// relative to its root: for orienting whole patches against each other.
class ParityUnionFind {
 public:
  explicit ParityUnionFind(uint32_t n) : parent_(n), parity_(n, 0) {
    for (uint32_t i = 0; i < n; ++i) parent_[i] = i;
  }
  // Root of x; `parity` = x's flip relative to the root.
  uint32_t find(uint32_t x, uint8_t& parity) {
    parity = 0;
    uint32_t root = x;
    while (parent_[root] != root) {
      parity ^= parity_[root];
      root = parent_[root];
    }
    // Path compression with parity fix-up.
    uint8_t p = parity;
    while (parent_[x] != root) {
      const uint32_t next = parent_[x];
      const uint8_t own = parity_[x];
      parent_[x] = root;
      parity_[x] = p;
      p ^= own;
      x = next;
    }
    return root;
  }
  // Requires flip(a) ^ flip(b) == relation; false when that contradicts
  // what is already known.
  bool unite(uint32_t a, uint32_t b, uint8_t relation) {
    uint8_t pa = 0, pb = 0;
    const uint32_t ra = find(a, pa), rb = find(b, pb);
    if (ra == rb) return (pa ^ pb) == relation;
    parent_[rb] = ra;
    parity_[rb] = pa ^ pb ^ relation;
    return true;
  }

 private:
  std::vector<uint32_t> parent_;
  std::vector<uint8_t> parity_;
};

// True when both faces of every two-face edge walk it in opposite
// directions (the recorded directions must be the faces' current ones). A
// sequential pass over the groups: no face is read.
bool two_face_edges_consistent(const EdgeGroups& groups) {
  for (uint32_t e = 0; e < groups.edge_count(); ++e) {
    if (groups.use_count(e) != 2) continue;
    if (groups.uses[groups.begin[e]].forward == groups.uses[groups.begin[e] + 1].forward)
      return false;
  }
  return true;
}

// After reverse_face on the faces in `to_flip`: their sides are the same
// edges walked the other way, side 0 <-> 2 (reverse_face swaps corners 1 and
// 2), side 1 stays. No membership changes, so the groups stay those a fresh
// build_edge_groups would give (uses of an edge stay in face order).
void flip_uses(EdgeGroups& groups, const std::vector<uint8_t>& to_flip) {
  for (EdgeUse& u : groups.uses) {
    if (!(to_flip[u.face] & kFaceReversed)) continue;
    u.local = static_cast<uint8_t>(2 - u.local);
    u.forward = !u.forward;
  }
}

// Step 2. Orients patches through required joins (a contradiction there is a
// non-orientable surface: error), then glues patches through optional joins
// where they agree and cuts the ones that contradict. Returns the number of
// flipped faces; marks cut joins and sets to_flip[f] for every face to
// flip (apply_flips does it, after the fan split).
Result<uint32_t> orient(const Mesh& mesh, const EdgeGroups& groups, std::vector<Join>& joins,
                        std::vector<uint8_t>& to_flip) {
  const uint32_t f_count = mesh.face_count();
  // Joins always pair opposite directions (match_nonmanifold_edge), so when
  // every two-face edge does too, every relation below asks for "no flip":
  // each face has parity 0 to its root, no join contradicts, every set keeps
  // its orientation. The answer is known without the pass over the faces.
  if (two_face_edges_consistent(groups)) {
    to_flip.assign(f_count, 0);
    return 0u;
  }
  ParityUnionFind faces(f_count);
  for (uint32_t e = 0; e < groups.edge_count(); ++e) {
    if (groups.use_count(e) != 2) continue;
    const EdgeUse& a = groups.uses[groups.begin[e]];
    const EdgeUse& b = groups.uses[groups.begin[e] + 1];
    if (!faces.unite(a.face, b.face, a.forward == b.forward ? 1 : 0)) {
      const Triangle& t = mesh.triangles[a.face];
      return make_error(ErrorCode::kNonManifold,
                        "the surface containing face " + std::to_string(a.face) + " (" +
                            where(mesh, t[0]) +
                            ", ...) cannot be oriented consistently (non-orientable, like a "
                            "Moebius strip)");
    }
  }
  for (Join& j : joins) {
    const EdgeUse& a = groups.uses[j.a];
    const EdgeUse& b = groups.uses[j.b];
    if (!faces.unite(a.face, b.face, a.forward == b.forward ? 1 : 0)) j.cut = true;
  }
  // Keep the majority's orientation in every glued set: flip the fewest.
  // balance[root] = faces to flip minus faces to keep relative to the root
  // (> 0 exactly when 2 * flipped > size). The second find is O(1): the
  // first pass compressed every path.
  std::vector<int32_t> balance(f_count, 0);
  for (uint32_t f = 0; f < f_count; ++f) {
    uint8_t flip = 0;
    balance[faces.find(f, flip)] += flip ? 1 : -1;
  }
  uint32_t flipped = 0;
  to_flip.assign(f_count, 0);
  for (uint32_t f = 0; f < f_count; ++f) {
    uint8_t flip = 0;
    const bool invert = balance[faces.find(f, flip)] > 0;
    if ((flip != 0) != invert) {
      to_flip[f] = 1;
      ++flipped;
    }
  }
  return flipped;
}

void apply_flips(Mesh& mesh, const std::vector<uint8_t>& to_flip) {
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    if (to_flip[f] & kFaceReversed) reverse_face(mesh, f);  // its corner data follows
  }
}

// Step 3, before the faces orient() chose are flipped. `sets`: the fans
// through the two-face edges (as choose_joins had them); the joins not cut
// are added here, so that pass over every edge is not made twice. Corners
// are visited in the order they will have once `to_flip` is applied (a
// flipped face's corners 1 and 2 trade places), so the copies are made in
// the same order as splitting after the flips would. Returns the number of
// vertex copies made; marks the faces given a copy kFaceRenumbered in
// `change` (which holds to_flip's kFaceReversed marks) and keeps their
// triangles from before in `old_triangles` (for update_edge_groups).
uint32_t split_fans(Mesh& mesh, const EdgeGroups& groups, const std::vector<Join>& joins,
                    UnionFind sets, std::vector<uint8_t>& change,
                    std::vector<std::pair<uint32_t, Triangle>>& old_triangles) {
  add_joins(mesh, groups, joins, sets);
  const uint32_t corner_count = 3 * mesh.face_count();
  // The fan that keeps the original vertex is the first one visited; the
  // others (few: only at non-manifold vertices) get a copy, found through a
  // small map, not an array over every corner (12 bytes a face).
  std::vector<uint32_t> owner(mesh.vertex_count(), kNone);
  std::unordered_map<uint32_t, uint32_t> copy_of_fan;
  uint32_t copies = 0;
  for (uint32_t visit = 0; visit < corner_count; ++visit) {
    const uint32_t local = visit % 3;
    const uint32_t c =
        (change[visit / 3] & kFaceReversed) && local != 0 ? visit - local + (3 - local) : visit;
    uint32_t& corner_vertex = mesh.triangles[c / 3][c % 3];
    const uint32_t v = corner_vertex;
    // Each corner is read once, before it is renumbered: v is the original.
    const uint32_t root = sets.find(c);
    if (owner[v] == kNone) {
      owner[v] = root;
      continue;
    }
    if (owner[v] == root) continue;
    auto [it, added] = copy_of_fan.try_emplace(root, 0u);
    if (added) {
      it->second = add_copy(mesh, v);
      ++copies;
    }
    // A face's corners are visited one after the other, so its triangle is
    // still the old one when its first corner is renumbered.
    if (!(change[c / 3] & kFaceRenumbered)) {
      old_triangles.emplace_back(c / 3, mesh.triangles[c / 3]);
      change[c / 3] |= kFaceRenumbered;
    }
    corner_vertex = it->second;
  }
  return copies;
}

// Step 4. Returns {faces detached, vertex copies made}; `change` gets
// kFaceRenumbered for every face given a copy (sized to the faces).
std::pair<uint32_t, uint32_t> detach_extra_faces(
    Mesh& mesh, const EdgeGroups& groups, std::vector<uint8_t>& change,
    std::vector<std::pair<uint32_t, Triangle>>& old_triangles) {
  std::vector<uint8_t> detach(mesh.face_count(), 0);
  bool any = false;
  for (uint32_t e = 0; e < groups.edge_count(); ++e) {
    if (groups.use_count(e) <= 2) continue;
    // Best consistently oriented pair by normals (no fans to consult here:
    // these faces already share both endpoints).
    const uint32_t first = groups.begin[e], count = groups.use_count(e);
    uint32_t keep_a = first, keep_b = kNone;
    float best = -4.0f;
    for (uint32_t i = first; i < first + count; ++i) {
      for (uint32_t k = i + 1; k < first + count; ++k) {
        if (groups.uses[i].forward == groups.uses[k].forward) continue;
        const float score =
            dot(face_normal(mesh, groups.uses[i].face), face_normal(mesh, groups.uses[k].face));
        if (score > best) {
          best = score;
          keep_a = i;
          keep_b = k;
        }
      }
    }
    for (uint32_t i = first; i < first + count; ++i) {
      if (i != keep_a && i != keep_b) {
        detach[groups.uses[i].face] = 1;
        any = true;
      }
    }
  }
  if (!any) return {0, 0};
  change.assign(mesh.face_count(), kFaceKept);
  std::vector<uint32_t> users(mesh.vertex_count(), 0);
  for (const Triangle& t : mesh.triangles) {
    for (uint32_t v : t) ++users[v];
  }
  uint32_t faces = 0, copies = 0;
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    if (!detach[f]) continue;
    ++faces;
    const Triangle before = mesh.triangles[f];
    for (uint32_t& v : mesh.triangles[f]) {
      if (users[v] <= 1) continue;  // already only this face's
      --users[v];
      v = add_copy(mesh, v);
      users.push_back(1);
      ++copies;
      if (change[f] == kFaceKept) old_triangles.emplace_back(f, before);
      change[f] = kFaceRenumbered;
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
                        "inconsistent orientation: faces " + std::to_string(uses[0].face) +
                            " and " + std::to_string(uses[1].face) + " walk the " +
                            edge_name(mesh, groups.lo[e], groups.hi[e]) + " in the same direction");
    }
  }
  UnionFind sets = two_face_fans(mesh, groups);
  std::vector<uint32_t> first_root(mesh.vertex_count(), kNone);
  for (uint32_t c = 0; c < 3 * mesh.face_count(); ++c) {
    const uint32_t v = mesh.triangles[c / 3][c % 3];
    const uint32_t root = sets.find(c);
    if (first_root[v] == kNone) {
      first_root[v] = root;
    } else if (first_root[v] != root) {
      return make_error(ErrorCode::kNonManifold, "non-manifold vertex: " + where(mesh, v) +
                                                     " joins several separate fans of faces");
    }
  }
  return {};
}

Result<RepairCounts> make_manifold(Mesh& mesh) {
  return make_manifold(mesh, build_edge_groups(mesh));
}

Result<RepairCounts> make_manifold(Mesh& mesh, EdgeGroups groups, EdgeGroups* final_groups) {
  UnionFind fans = two_face_fans(mesh, groups);
  return make_manifold(mesh, std::move(groups), std::move(fans), final_groups);
}

// Room for the vertex copies the repair appends, made now: growing the
// arrays by doubling in the middle of the fan split would hold the old and
// the new array at once beside everything the split needs (the peak).
// Pages the copies never reach cost no memory.
template <class T>
void leave_room(std::vector<T>& values) {
  if (values.empty()) return;
  const size_t room = values.size() + values.size() / 32 + 64;
  if (values.capacity() < room) values.reserve(room);
}

Result<RepairCounts> make_manifold(Mesh& mesh, EdgeGroups groups, UnionFind first_fans,
                                   EdgeGroups* final_groups) {
  leave_room(mesh.positions);
  leave_room(mesh.normals);
  leave_room(mesh.colors);
  leave_room(mesh.texcoords);
  RepairCounts counts;
  constexpr int kMaxRounds = 32;
  std::string last_problem;
  for (int round = 0; round < kMaxRounds; ++round) {
    // `groups` are those of the mesh as it is now: every change below
    // updates them in place (update_edge_groups), as a fresh build would
    // give them, instead of building them again (the old and the new
    // groups are never alive at once).
    UnionFind fans = round == 0 ? std::move(first_fans) : two_face_fans(mesh, groups);
    std::vector<Join> joins = choose_joins(mesh, groups, fans);
    std::vector<uint8_t> change;  // orient's flips, then the split's copies
    auto flipped = orient(mesh, groups, joins, change);
    if (!flipped) return tl::unexpected(flipped.error());
    counts.flipped_faces += *flipped;
    // The split works on the faces as they are (so the fans' corner numbers
    // still hold), the flips come after it. Flipping changes no vertex of
    // any face, so groups and joins stay valid afterwards too (only the
    // directions recorded in them are stale).
    std::vector<std::pair<uint32_t, Triangle>> old_triangles;
    const uint32_t split = split_fans(mesh, groups, joins, std::move(fans), change, old_triangles);
    apply_flips(mesh, change);
    counts.split_vertices += split;
    joins = {};
    if (split > 0) update_edge_groups(groups, mesh, change, old_triangles);
    old_triangles.clear();
    // Without a split the detaching reads the directions from before the
    // flips, as it always has (the choice of pair, hence the output, must
    // not change); they are brought up to date after it.
    std::vector<uint8_t> detached_change;
    const auto [detached, copies] =
        detach_extra_faces(mesh, groups, detached_change, old_triangles);
    counts.detached_faces += detached;
    counts.split_vertices += copies;
    if (split == 0 && *flipped > 0) flip_uses(groups, change);
    change = {};
    // Detaching faces nearly always leaves new non-manifold vertices: go
    // straight to another round.
    if (detached > 0) {
      update_edge_groups(groups, mesh, detached_change, old_triangles);
      continue;
    }
    // Nothing detached: no edge has more than two faces now. Every vertex
    // (original or copy) is one fan: its corners were one set of this
    // round's joins, each join is between two faces that now share an edge
    // of the same two vertices (join_across joins both endpoints), and that
    // edge has at most two faces, so it is a two-face edge joining them. So
    // the corner table accepts the mesh exactly when every two-face edge is
    // walked both ways, which the groups (current again) tell without
    // building it. When one is not, the table is built for its message.
    if (two_face_edges_consistent(groups)) {
      if (final_groups) *final_groups = std::move(groups);
      return counts;
    }
    auto adjacency = Adjacency::build(mesh);
    if (adjacency) {
      if (final_groups) *final_groups = std::move(groups);
      return counts;
    }
    last_problem = adjacency.error().message;
    if (*flipped == 0 && split == 0) break;  // stuck
  }
  return make_error(ErrorCode::kNonManifold,
                    "non-manifold repair did not converge: " + last_problem);
}

}  // namespace meshstream
