// Adaptive level: faces are kept, bisected (green), split 1-to-4 (red), or,
// for a green pair whose parent must be refined, replaced by the parent's
// 1-to-4 split (red-green refinement: a green triangle is never split again).
//
// The result's corner table is built without hashing. A kept face (most
// faces, from the second level on) lands at a known output face, so its
// corners map one to one; every other parent corner records which output
// corner(s) face its edge (two when the edge was split: slot_a near
// vertex(next(c)), slot_b near vertex(prev(c))). A final pass pairs the two
// sides of every parent edge. Edges inside one parent are linked while its
// children are written. `across` is not kept on adaptive levels: the few
// edge points of a level look their wings up instead.
//
// For the next level, the split also writes each output face's unit normal
// (copied for a kept face: same three positions, same bits) and whether the
// face is new ("fresh"): flatness is re-tested only where a face changed.
#include <array>
#include <cstring>

#include "common/asa/butterfly_rules.h"
#include "common/asa/edge_points.h"
#include "common/asa/split.h"

namespace meshstream::asa {
namespace {

// Writes output faces into arrays pre-sized to the exact output size (no
// push_back in the loop).
struct Emitter {
  LevelMesh& out;
  std::vector<FaceKind>* face_kind;
  bool topology;
  bool track_source = false;
  bool normals = false;  // write next-level normals and fresh flags
  uint32_t source = 0;   // input face of the parent being split
  uint32_t count = 0;    // faces written
  uint32_t* tri = nullptr;
  uint32_t* valence = nullptr;  // faces per vertex, with topology

  void start(size_t total) {
    out.triangles.resize(total);
    tri = total ? out.triangles.front().data() : nullptr;
    if (face_kind) face_kind->resize(total);
    if (track_source) out.source.resize(total);
    if (topology) {
      out.opposite.resize(3 * total);
      out.across.clear();  // not kept on adaptive levels (see edge_points.h)
      out.feature_edge.resize(3 * total);
      out.green.resize(total);
    }
    if (normals) {
      out.normals.resize(total);
      out.fresh.resize(total);
    }
  }
  // A new face: its internal corners are linked by the caller; the corners
  // on parent edges get their links in the final pass.
  uint32_t emit(uint32_t a, uint32_t b, uint32_t c, uint8_t green, FaceKind kind) {
    const uint32_t f = count++;
    tri[3 * f] = a;
    tri[3 * f + 1] = b;
    tri[3 * f + 2] = c;
    if (face_kind) (*face_kind)[f] = kind;
    if (track_source) out.source[f] = source;
    if (topology) {
      for (uint32_t i = 0; i < 3; ++i) out.feature_edge[3 * f + i] = 0;
      out.green[f] = green;
      ++valence[a];
      ++valence[b];
      ++valence[c];
    }
    if (normals) {
      const Vec3f* p = out.positions.data();
      out.normals[f] = normalized(cross(p[b] - p[a], p[c] - p[a]));
      out.fresh[f] = 1;
    }
    return f;
  }
  uint32_t vertex(uint32_t corner) const { return tri[corner]; }
  // Corners x and y face each other.
  void link(uint32_t x, uint32_t y) {
    out.opposite[x] = y;
    out.opposite[y] = x;
  }
};

// A parent edge seen from one side: from p to q, split at s (or kNone),
// faced by parent corner `corner`.
struct BorderEdge {
  uint32_t corner, p, q, s;
};

// Links the children of one opened green pair (up to six triangles starting
// at face `first`) among themselves and records the parent corners' slots,
// by matching directed edges; only used for the rare opened pairs.
void link_local(Emitter& e, uint32_t first, uint32_t count, const std::array<BorderEdge, 4>& border,
                const uint8_t* feature_edge, SplitScratch& s) {
  const uint32_t c0 = 3 * first, c1 = 3 * (first + count);
  auto from = [&](uint32_t c) { return e.vertex(next_corner(c)); };
  auto to = [&](uint32_t c) { return e.vertex(prev_corner(c)); };
  auto find = [&](uint32_t u, uint32_t w) {
    for (uint32_t c = c0; c < c1; ++c)
      if (from(c) == u && to(c) == w) return c;
    return kNone;
  };
  if (e.topology) {
    for (uint32_t c = c0; c < c1; ++c) {
      const uint32_t o = find(to(c), from(c));
      if (o != kNone) e.out.opposite[c] = o;
    }
  }
  for (const BorderEdge& b : border) {
    if (b.s == kNone) {
      s.slot_a[b.corner] = s.slot_b[b.corner] = find(b.p, b.q);
    } else {
      s.slot_a[b.corner] = find(b.p, b.s);
      s.slot_b[b.corner] = find(b.s, b.q);
    }
    if (e.topology) {
      e.out.feature_edge[s.slot_a[b.corner]] = feature_edge[b.corner];
      e.out.feature_edge[s.slot_b[b.corner]] = feature_edge[b.corner];
    }
  }
}

// Numbers one new vertex per split edge, in corner order, and lists the
// corner that names each (so later loops touch only split edges). Split flags
// are sparse on later levels: they are skipped eight at a time. Returns E.
uint32_t name_split_edges(const LevelView& m, const uint8_t* split, SplitScratch& s) {
  const uint32_t V = m.vertex_count, corners = 3 * m.face_count;
  const uint32_t* opp = m.opposite;
  s.edge_vertex.assign(corners, kNone);
  s.naming.clear();
  uint32_t E = 0;
  uint32_t* edge_vertex = s.edge_vertex.data();
  auto name = [&](uint32_t c) {
    const uint32_t o = opp[c];
    if (o == kNone || c < o) {
      edge_vertex[c] = V + E++;
      s.naming.push_back(c);
    } else {
      edge_vertex[c] = edge_vertex[o];
    }
  };
  uint32_t c = 0;
  for (; c + 8 <= corners; c += 8) {
    uint64_t word;
    std::memcpy(&word, split + c, 8);
    if (word == 0) continue;
    for (uint32_t i = 0; i < 8; ++i)
      if (split[c + i]) name(c + i);
  }
  for (; c < corners; ++c)
    if (split[c]) name(c);
  return E;
}

// The level's vertices: old ones copied, the E new ones placed by the
// Butterfly rules, their attributes averaged from their edge's endpoints.
void place_vertices(const SplitInput& in, uint32_t E, SplitScratch& s, LevelMesh& out) {
  const LevelView& m = in.mesh;
  const uint32_t V = m.vertex_count;
  const uint32_t* cv = m.corner_vertex;
  out.positions.resize(static_cast<size_t>(V) + E);
  std::memcpy(out.positions.data(), m.positions, sizeof(Vec3f) * V);
  start_vertex_attributes(in, V, E, out);
  compute_edge_points(m, s.edge_vertex.data(), V, E, *in.weights, in.placement,
                      out.positions.data(), s.points, &s.naming);
  if (in.colors == nullptr && in.texcoords == nullptr && in.parents == nullptr) return;
  for (uint32_t k = 0; k < E; ++k) {
    const uint32_t c = s.naming[k];
    average_vertex_attributes(in, cv[next_corner(c)], cv[prev_corner(c)], V + k, out);
  }
}

// The exact output face count, so the arrays are written in place; with
// topology, a kept face's first output corner (kNone for other faces). Sets
// s.fresh_count.
size_t count_output_faces(const LevelView& m, const uint8_t* action, const uint8_t* split,
                          bool topo, SplitScratch& s) {
  const uint32_t F = m.face_count;
  if (topo) {
    s.slot_a.resize(3 * F);
    s.slot_b.resize(3 * F);
    s.kept_base.resize(F);
  }
  uint32_t* kept_base = topo ? s.kept_base.data() : nullptr;
  size_t total = 0, kept = 0;
  for (uint32_t f = 0; f < F; ++f) {
    const uint8_t a = action[f];
    if (topo) kept_base[f] = a == kKeep ? static_cast<uint32_t>(3 * total) : kNone;
    switch (a) {
      case kKeep:
        total += 1;
        ++kept;
        break;
      case kBisect:
        total += 2;
        break;
      case kRed:
        total += 4;
        break;
      case kOpened:
        if (m.green[f] == kGreenFirst)
          total += 4 + (split[3 * f] ? 1 : 0) + (split[3 * f + 3] ? 1 : 0);
        break;
    }
  }
  s.fresh_count = static_cast<uint32_t>(total - kept);
  return total;
}

// Writes every parent face's children in parent order (see the file
// comment); with topology, links the edges inside each parent and records
// the slots of its edges for pair_parent_edges.
struct ChildWriter {
  const SplitInput& in;
  const LevelView& m;
  const uint8_t* split;
  SplitScratch& s;
  LevelMesh& out;
  Emitter& e;
  std::vector<FaceKind>* face_kind;

  void set_slot(uint32_t parent, uint32_t a, uint32_t b) {
    s.slot_a[parent] = a;
    s.slot_b[parent] = b;
    out.feature_edge[a] = m.feature_edge[parent];
    out.feature_edge[b] = m.feature_edge[parent];
  }

  // A run of unchanged faces from f is copied in bulk; their links are made
  // in the final pass. Returns the face after the run.
  uint32_t copy_kept_run(uint32_t f, const uint8_t* action) {
    const uint32_t F = m.face_count;
    const uint32_t* cv = m.corner_vertex;
    const uint8_t* fe = m.feature_edge;
    uint32_t end = f + 1;
    while (end < F && action[end] == kKeep) ++end;
    const uint32_t n = end - f, g = e.count;
    e.count += n;
    std::memcpy(e.tri + 3 * static_cast<size_t>(g), cv + 3 * static_cast<size_t>(f),
                3 * sizeof(uint32_t) * n);
    if (face_kind) std::memset(face_kind->data() + g, static_cast<int>(FaceKind::kUntouched), n);
    if (e.track_source) std::memcpy(out.source.data() + g, in.source + f, sizeof(uint32_t) * n);
    if (e.topology) {
      std::memcpy(out.feature_edge.data() + 3 * static_cast<size_t>(g),
                  fe + 3 * static_cast<size_t>(f), 3 * n);
      if (m.green)
        std::memcpy(out.green.data() + g, m.green + f, n);
      else
        std::memset(out.green.data() + g, kNotGreen, n);
    }
    if (e.normals) {
      std::memcpy(out.normals.data() + g, in.normals + f, sizeof(Vec3f) * n);
      std::memset(out.fresh.data() + g, 0, n);
    }
    return end;
  }

  // A replaced face: its faces-per-vertex share goes (its children add
  // theirs); its vertices may end with a valence not seen before.
  void retire_parent(const uint32_t v[3]) {
    --e.valence[v[0]];
    --e.valence[v[1]];
    --e.valence[v[2]];
    s.touched.insert(s.touched.end(), v, v + 3);
  }

  void write_red(uint32_t f, const uint32_t v[3]) {
    const uint32_t mid[3] = {s.edge_vertex[3 * f], s.edge_vertex[3 * f + 1],
                             s.edge_vertex[3 * f + 2]};
    const uint32_t base = e.emit(v[0], mid[2], mid[1], kNotGreen, FaceKind::kTarget);
    e.emit(v[1], mid[0], mid[2], kNotGreen, FaceKind::kTarget);
    e.emit(v[2], mid[1], mid[0], kNotGreen, FaceKind::kTarget);
    e.emit(mid[0], mid[1], mid[2], kNotGreen, FaceKind::kTarget);
    if (!e.topology) return;
    const uint32_t b = 3 * base;
    for (uint32_t i = 0; i < 3; ++i) e.link(b + 3 * i, b + 9 + i);
    for (uint32_t k = 0; k < 3; ++k) {
      set_slot(3 * f + k, b + 3 * ((k + 1) % 3) + 2, b + 3 * ((k + 2) % 3) + 1);
    }
  }

  void write_bisected(uint32_t f, const uint32_t v[3]) {
    uint32_t k = 0;
    while (!split[3 * f + k]) ++k;
    const uint32_t A = v[k], B = v[(k + 1) % 3], C = v[(k + 2) % 3];
    const uint32_t X = s.edge_vertex[3 * f + k];
    const uint32_t g1 = e.emit(A, B, X, kGreenFirst, FaceKind::kBisected);
    const uint32_t g2 = e.emit(A, X, C, kGreenSecond, FaceKind::kBisected);
    if (!e.topology) return;
    e.link(3 * g1 + 1, 3 * g2 + 2);
    set_slot(3 * f + k, 3 * g1, 3 * g2);
    set_slot(3 * f + (k + 2) % 3, 3 * g1 + 2, 3 * g1 + 2);  // A-B
    set_slot(3 * f + (k + 1) % 3, 3 * g2 + 1, 3 * g2 + 1);  // C-A
  }

  // A green pair (f, f + 1) whose parent is refined: the parent's 1-to-4
  // split, each outer child on a split edge bisected in turn.
  void write_opened_pair(uint32_t f, const uint32_t v[3]) {
    const uint32_t* cv = m.corner_vertex;
    const uint32_t g = f + 1;
    const uint32_t A = v[0], B = v[1], M = v[2], C = cv[3 * g + 2];
    const uint32_t mab = s.edge_vertex[3 * f + 2], mca = s.edge_vertex[3 * g + 1];
    const uint32_t X = s.edge_vertex[3 * f], Y = s.edge_vertex[3 * g];
    const uint32_t first = e.emit(A, mab, mca, kNotGreen, FaceKind::kTarget);
    e.emit(mab, M, mca, kNotGreen, FaceKind::kTarget);
    uint32_t count = 2;
    if (X == kNone) {
      e.emit(B, M, mab, kNotGreen, FaceKind::kTarget);
      ++count;
    } else {
      e.emit(mab, B, X, kGreenFirst, FaceKind::kBisected);
      e.emit(mab, X, M, kGreenSecond, FaceKind::kBisected);
      count += 2;
    }
    if (Y == kNone) {
      e.emit(C, mca, M, kNotGreen, FaceKind::kTarget);
      ++count;
    } else {
      e.emit(mca, M, Y, kGreenFirst, FaceKind::kBisected);
      e.emit(mca, Y, C, kGreenSecond, FaceKind::kBisected);
      count += 2;
    }
    if (!e.topology) return;
    const std::array<BorderEdge, 4> border{{
        {3 * f + 2, A, B, mab},  // AB
        {3 * f, B, M, X},        // BM
        {3 * g, M, C, Y},        // MC
        {3 * g + 1, C, A, mca},  // CA
    }};
    link_local(e, first, count, border, m.feature_edge, s);
    s.slot_a[3 * f + 1] = s.slot_b[3 * f + 1] = kNone;  // A-M vanished
    s.slot_a[3 * g + 2] = s.slot_b[3 * g + 2] = kNone;
  }

  void write_all(const uint8_t* action) {
    const uint32_t F = m.face_count;
    const uint32_t* cv = m.corner_vertex;
    for (uint32_t f = 0; f < F; ++f) {
      if (action[f] == kKeep) {
        f = copy_kept_run(f, action) - 1;
        continue;
      }
      const uint32_t v[3] = {cv[3 * f], cv[3 * f + 1], cv[3 * f + 2]};
      if (e.track_source) e.source = in.source[f];
      if (e.topology) retire_parent(v);
      switch (action[f]) {
        case kKeep:
          break;  // handled above
        case kRed:
          write_red(f, v);
          break;
        case kBisect:
          write_bisected(f, v);
          break;
        case kOpened:
          // The pair is written at its first half.
          if (m.green[f] == kGreenFirst) write_opened_pair(f, v);
          break;
      }
    }
  }
};

// Pairs the two sides of every parent edge in the output corner table.
void pair_parent_edges(const LevelView& m, const SplitScratch& s, LevelMesh& out) {
  const uint32_t F = m.face_count;
  const uint32_t* opp = m.opposite;
  const uint32_t* kept_base = s.kept_base.data();
  uint32_t* oo = out.opposite.data();
  auto side_a = [&](uint32_t c) {
    const uint32_t base = kept_base[c / 3];
    return base != kNone ? base + c % 3 : s.slot_a[c];
  };
  auto side_b = [&](uint32_t c) {
    const uint32_t base = kept_base[c / 3];
    return base != kNone ? base + c % 3 : s.slot_b[c];
  };
  for (uint32_t f = 0; f < F; ++f) {
    const uint32_t base = kept_base[f];
    if (base != kNone) {
      // A run of kept faces: one output corner per parent corner, shifted by
      // the same amount across the run, so a neighbour inside the run needs
      // no lookup; across an unsplit edge to elsewhere lies a kept face or
      // one corner of a refined one.
      uint32_t end = f + 1;
      while (end < F && kept_base[end] != kNone) ++end;
      const uint32_t first = 3 * f, last = 3 * end;
      const uint32_t shift = base - first;
      for (uint32_t c = first; c < last; ++c) {
        const uint32_t o = opp[c];
        oo[c + shift] = o == kNone ? kNone : (o - first < last - first ? o + shift : side_b(o));
      }
      f = end - 1;
      continue;
    }
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t c = 3 * f + k, o = opp[c];
      const uint32_t a = s.slot_a[c];
      if (a == kNone) continue;  // the internal edge of an opened pair
      const uint32_t b = s.slot_b[c];
      if (o == kNone) {
        oo[a] = oo[b] = kNone;
        continue;
      }
      oo[a] = side_b(o);
      oo[b] = side_a(o);
    }
  }
}

}  // namespace

void split_adaptive(const SplitInput& in, const ClosureBuffers& closure, SplitScratch& s,
                    LevelMesh& out, std::vector<FaceKind>* face_kind) {
  const LevelView& m = in.mesh;
  const uint32_t V = m.vertex_count;
  const uint8_t* split = closure.edge_split.data();
  const uint8_t* action = closure.action.data();
  const bool topo = in.want_topology;

  const uint32_t E = name_split_edges(m, split, s);
  place_vertices(in, E, s, out);

  Emitter e{.out = out, .face_kind = face_kind, .topology = topo};
  e.track_source = in.source != nullptr;
  e.normals = topo && in.normals != nullptr;
  if (!e.track_source) out.source.clear();
  if (!e.normals) {
    out.normals.clear();
    out.fresh.clear();
  }
  e.start(count_output_faces(m, action, split, topo, s));
  s.touched.clear();
  if (topo) {
    // Faces per vertex: the parent's counts, minus every replaced face, plus
    // every new one (counted while the faces are written).
    out.valence.resize(static_cast<size_t>(V) + E);
    std::memcpy(out.valence.data(), m.valence, sizeof(uint32_t) * V);
    std::memset(out.valence.data() + V, 0, sizeof(uint32_t) * E);
    e.valence = out.valence.data();
  }
  ChildWriter writer{
      .in = in, .m = m, .split = split, .s = s, .out = out, .e = e, .face_kind = face_kind};
  writer.write_all(action);
  if (!topo) return;

  pair_parent_edges(m, s, out);
  // Features for the next level: old vertices keep theirs, new ones have two
  // when their edge was a feature edge.
  out.vertex_features.resize(static_cast<size_t>(V) + E);
  std::memcpy(out.vertex_features.data(), m.vertex_features, V);
  for (uint32_t k = 0; k < E; ++k) out.vertex_features[V + k] = m.feature_edge[s.naming[k]] ? 2 : 0;
}

}  // namespace meshstream::asa
