#include "common/mesh/edge_groups.h"

#include <algorithm>
#include <cstring>

namespace meshstream {

EdgeGroups build_edge_groups(const Mesh& mesh) {
  const uint32_t n = mesh.vertex_count();
  const uint32_t face_count = mesh.face_count();
  auto usable = [n](const Triangle& t) {
    return t[0] < n && t[1] < n && t[2] < n && t[0] != t[1] && t[1] != t[2] && t[2] != t[0];
  };

  // Bucket every face side by its smaller vertex (CSR), then sort each small
  // bucket by the larger vertex: linear overall instead of one big sort.
  std::vector<uint32_t> offset(static_cast<size_t>(n) + 1, 0);
  for (const Triangle& t : mesh.triangles) {
    if (!usable(t)) continue;
    for (int i = 0; i < 3; ++i) ++offset[std::min(t[i], t[(i + 1) % 3]) + 1];
  }
  for (uint32_t v = 0; v < n; ++v) offset[v + 1] += offset[v];
  // The uses go straight into their buckets, in face order, each with its
  // larger vertex beside it (a temporary 4 bytes a side), so the buckets are
  // sorted without going back to the faces: at millions of faces that
  // random access was most of the cost.
  EdgeGroups groups;
  groups.uses.resize(offset[n]);
  std::vector<uint32_t> larger(offset[n]);
  {
    std::vector<uint32_t> fill(offset.begin(), offset.end() - 1);
    for (uint32_t f = 0; f < face_count; ++f) {
      const Triangle& t = mesh.triangles[f];
      if (!usable(t)) continue;
      for (uint8_t i = 0; i < 3; ++i) {
        const uint32_t a = t[i], b = t[i == 2 ? 0 : i + 1];
        const uint32_t slot = fill[std::min(a, b)]++;
        groups.uses[slot] = EdgeUse{f, i, a < b};
        larger[slot] = std::max(a, b);
      }
    }
  }
  // Each bucket (the sides whose smaller vertex is v: about 6, 3 edges of 2
  // faces) is sorted by its larger vertex. Stable: the uses of one
  // edge stay in face order (deterministic repair). Insertion sort in place
  // for the usual few; std::stable_sort (through a buffer) for a big fan.
  struct Side {
    uint32_t hi;
    EdgeUse use;
  };
  std::vector<Side> big;
  // Every edge of a closed mesh has two sides; boundaries and the repair's
  // splits (update_edge_groups) add a few more edges: room for them, so the
  // arrays are not copied to grow (pages never touched cost no memory).
  const size_t edge_room = groups.uses.size() / 2 + groups.uses.size() / 32 + 16;
  groups.lo.reserve(edge_room);
  groups.hi.reserve(edge_room);
  groups.begin.reserve(edge_room + 1);
  for (uint32_t v = 0; v < n; ++v) {
    const uint32_t first = offset[v], last = offset[v + 1];
    if (last - first > 32) {
      big.clear();
      for (uint32_t k = first; k < last; ++k) big.push_back({larger[k], groups.uses[k]});
      std::stable_sort(big.begin(), big.end(),
                       [](const Side& a, const Side& b) { return a.hi < b.hi; });
      for (uint32_t k = first; k < last; ++k) {
        larger[k] = big[k - first].hi;
        groups.uses[k] = big[k - first].use;
      }
    } else {
      for (uint32_t k = first + 1; k < last; ++k) {
        const uint32_t hi = larger[k];
        const EdgeUse use = groups.uses[k];
        uint32_t hole = k;
        for (; hole > first && larger[hole - 1] > hi; --hole) {
          larger[hole] = larger[hole - 1];
          groups.uses[hole] = groups.uses[hole - 1];
        }
        larger[hole] = hi;
        groups.uses[hole] = use;
      }
    }
    for (uint32_t k = first; k < last; ++k) {
      if (k == first || larger[k] != larger[k - 1]) {
        groups.lo.push_back(v);
        groups.hi.push_back(larger[k]);
        groups.begin.push_back(k);
      }
    }
  }
  groups.begin.push_back(static_cast<uint32_t>(groups.uses.size()));
  return groups;
}

namespace {

// The index of edge (lo, hi) in `groups`, or kNoEdge.
constexpr uint32_t kNoEdge = 0xFFFFFFFFu;
uint32_t find_edge(const EdgeGroups& groups, uint32_t lo, uint32_t hi) {
  uint32_t first = 0, last = groups.edge_count();
  while (first < last) {
    const uint32_t mid = first + (last - first) / 2;
    if (groups.lo[mid] < lo || (groups.lo[mid] == lo && groups.hi[mid] < hi)) {
      first = mid + 1;
    } else {
      last = mid;
    }
  }
  return first < groups.edge_count() && groups.lo[first] == lo && groups.hi[first] == hi ? first
                                                                                         : kNoEdge;
}

}  // namespace

void update_edge_groups(EdgeGroups& groups, const Mesh& mesh, const std::vector<uint8_t>& change,
                        const std::vector<std::pair<uint32_t, Triangle>>& old_triangles) {
  // The renumbered faces' sides as they are now, in the groups' order:
  // by edge, then by face (a face has one side on an edge).
  struct Side {
    uint32_t lo, hi;
    EdgeUse use;
  };
  std::vector<Side> added;
  // The old edges holding a side of a changed face: only they are looked
  // at one use at a time, the rest moves in blocks.
  std::vector<uint32_t> touched;
  bool lost = false;  // a side not in the groups: they were not this mesh's
  auto touch = [&](const Triangle& t) {
    for (int i = 0; i < 3; ++i) {
      const uint32_t a = t[i], b = t[(i + 1) % 3];
      const uint32_t e = find_edge(groups, std::min(a, b), std::max(a, b));
      if (e == kNoEdge) lost = true;
      touched.push_back(e);
    }
  };
  for (const auto& [f, old] : old_triangles) touch(old);
  uint32_t renumbered = 0;
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    if (change[f] == kFaceKept) continue;
    if (change[f] == kFaceReversed) touch(mesh.triangles[f]);
    if (!(change[f] & kFaceRenumbered)) continue;
    ++renumbered;
    const Triangle& t = mesh.triangles[f];
    for (uint8_t i = 0; i < 3; ++i) {
      const uint32_t a = t[i], b = t[i == 2 ? 0 : i + 1];
      added.push_back({std::min(a, b), std::max(a, b), EdgeUse{f, i, a < b}});
    }
  }
  auto build_afresh = [&groups, &mesh] {  // not what the caller promised: be right, not fast
    groups = {};
    groups = build_edge_groups(mesh);
  };
  if (lost || old_triangles.size() != renumbered) return build_afresh();
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  std::sort(added.begin(), added.end(), [](const Side& x, const Side& y) {
    if (x.lo != y.lo) return x.lo < y.lo;
    if (x.hi != y.hi) return x.hi < y.hi;
    return x.use.face < y.use.face;
  });

  // Pass 1, forward: drop the renumbered faces' old uses and the edges left
  // without a use; reverse the reversed faces' sides (side 0 <-> 2, as
  // reverse_face swaps corners 1 and 2). The untouched edges between move
  // down in blocks, their use offsets by the same amount. Writes never pass
  // reads.
  std::vector<EdgeUse>& uses = groups.uses;
  const uint32_t old_edges = groups.edge_count();
  uint32_t kept_uses = 0, kept_edges = 0;
  auto move_block = [&](uint32_t from, uint32_t to) {  // old edges [from, to)
    if (from == to) return;
    const uint32_t first_use = groups.begin[from], end_use = groups.begin[to];
    const uint32_t shift = first_use - kept_uses;
    if (shift > 0 || kept_edges != from) {
      std::memmove(uses.data() + kept_uses, uses.data() + first_use,
                   (end_use - first_use) * sizeof(EdgeUse));
      std::memmove(groups.lo.data() + kept_edges, groups.lo.data() + from,
                   (to - from) * sizeof(uint32_t));
      std::memmove(groups.hi.data() + kept_edges, groups.hi.data() + from,
                   (to - from) * sizeof(uint32_t));
      for (uint32_t i = 0; i < to - from; ++i)
        groups.begin[kept_edges + i] = groups.begin[from + i] - shift;
    }
    kept_uses += end_use - first_use;
    kept_edges += to - from;
  };
  uint32_t next = 0;  // first old edge not yet moved
  uint32_t removed = 0;
  for (const uint32_t e : touched) {
    move_block(next, e);
    next = e + 1;
    const uint32_t first = kept_uses;
    for (uint32_t k = groups.begin[e]; k < groups.begin[e + 1]; ++k) {
      EdgeUse u = uses[k];
      const uint8_t c = change[u.face];
      if (c & kFaceRenumbered) {
        ++removed;
        continue;
      }
      if (c & kFaceReversed) {
        u.local = static_cast<uint8_t>(2 - u.local);
        u.forward = !u.forward;
      }
      uses[kept_uses++] = u;
    }
    if (kept_uses == first) continue;
    groups.lo[kept_edges] = groups.lo[e];
    groups.hi[kept_edges] = groups.hi[e];
    groups.begin[kept_edges] = first;
    ++kept_edges;
  }
  move_block(next, old_edges);
  if (removed != 3 * renumbered) return build_afresh();  // an old triangle was wrong

  // Pass 2, backward: merge the added sides in, writing from the top of the
  // arrays down. The uses end at their old size again (faces keep three
  // sides); the edges get at most one per distinct added edge more, the
  // surplus (added edges that exist already) is closed up afterwards.
  uint32_t added_edges = 0;
  for (size_t i = 0; i < added.size(); ++i) {
    added_edges += i == 0 || added[i].lo != added[i - 1].lo || added[i].hi != added[i - 1].hi;
  }
  const uint32_t edge_room = kept_edges + added_edges;
  if (edge_room + 1 > groups.begin.capacity()) {  // rare: build_edge_groups leaves room
    groups.lo.reserve(edge_room + edge_room / 32);
    groups.hi.reserve(edge_room + edge_room / 32);
    groups.begin.reserve(edge_room + edge_room / 32 + 1);
  }
  groups.lo.resize(edge_room);
  groups.hi.resize(edge_room);
  groups.begin.resize(edge_room);
  auto old_key = [&groups](int64_t i) {
    return (static_cast<uint64_t>(groups.lo[i]) << 32) | groups.hi[i];
  };
  auto added_key = [&added](int64_t i) {
    return (static_cast<uint64_t>(added[i].lo) << 32) | added[i].hi;
  };
  uint32_t use_out = static_cast<uint32_t>(uses.size());
  uint32_t edge_out = edge_room;
  uint32_t old_end = kept_uses;  // end of the uses of old edge `e`
  int64_t e = static_cast<int64_t>(kept_edges) - 1;
  int64_t a = static_cast<int64_t>(added.size()) - 1;
  // Invariants: use_out = old_end + the added uses left, edge_out = e + 1 +
  // the distinct added edges left. So once every added side is in, the old
  // edges left are where they belong already.
  while (a >= 0) {
    const uint64_t next_added = added_key(a);
    if (e >= 0 && old_key(e) > next_added) {
      // Old edges above the next added one move up as one block: memmove,
      // and their use offsets shift by the same amount.
      int64_t lo = 0, hi = e;  // first old edge in [0, e] above next_added
      while (lo < hi) {
        const int64_t mid = (lo + hi) / 2;
        if (old_key(mid) > next_added) {
          hi = mid;
        } else {
          lo = mid + 1;
        }
      }
      const uint32_t first_use = groups.begin[lo];
      const uint32_t shift = use_out - old_end;
      const uint32_t edges = static_cast<uint32_t>(e - lo + 1);
      std::memmove(uses.data() + first_use + shift, uses.data() + first_use,
                   (old_end - first_use) * sizeof(EdgeUse));
      const uint32_t dst = edge_out - edges;
      std::memmove(groups.lo.data() + dst, groups.lo.data() + lo, edges * sizeof(uint32_t));
      std::memmove(groups.hi.data() + dst, groups.hi.data() + lo, edges * sizeof(uint32_t));
      std::memmove(groups.begin.data() + dst, groups.begin.data() + lo, edges * sizeof(uint32_t));
      for (uint32_t i = dst; i < edge_out; ++i) groups.begin[i] += shift;
      use_out -= old_end - first_use;
      edge_out = dst;
      old_end = first_use;
      e = lo - 1;
      continue;
    }
    // One edge: the next added one, with the old uses of the same edge if
    // there is one, merged by face, largest first.
    const bool with_old = e >= 0 && old_key(e) == next_added;
    const uint32_t old_first = with_old ? groups.begin[e] : old_end;
    uint32_t k = old_end;
    while (a >= 0 && added_key(a) == next_added) {
      if (k > old_first && uses[k - 1].face > added[a].use.face) {
        uses[--use_out] = uses[--k];
      } else {
        uses[--use_out] = added[a--].use;
      }
    }
    while (k > old_first) uses[--use_out] = uses[--k];
    --edge_out;
    groups.lo[edge_out] = static_cast<uint32_t>(next_added >> 32);
    groups.hi[edge_out] = static_cast<uint32_t>(next_added);
    groups.begin[edge_out] = use_out;
    if (with_old) {
      old_end = old_first;
      --e;
    }
  }
  // Close the gap left by added edges that were there already.
  const uint32_t gap_begin = static_cast<uint32_t>(e + 1), gap = edge_out - gap_begin;
  if (gap > 0) {
    groups.lo.erase(groups.lo.begin() + gap_begin, groups.lo.begin() + edge_out);
    groups.hi.erase(groups.hi.begin() + gap_begin, groups.hi.begin() + edge_out);
    groups.begin.erase(groups.begin.begin() + gap_begin, groups.begin.begin() + edge_out);
  }
  groups.begin.push_back(static_cast<uint32_t>(uses.size()));
}

}  // namespace meshstream
