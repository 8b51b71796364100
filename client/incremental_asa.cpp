#include "client/incremental_asa.h"

#include <algorithm>
#include <cstring>

namespace meshstream::client {

namespace {

constexpr uint32_t kNoVertex = 0xffffffffu;

bool same_bits(const Vec3f& a, const Vec3f& b) { return std::memcmp(&a, &b, sizeof(Vec3f)) == 0; }

uint32_t group_size(FaceKind k) {
  switch (k) {
    case FaceKind::kUntouched: return 1;
    case FaceKind::kBisected: return 2;
    case FaceKind::kTarget: return 4;
  }
  return 0;
}

void remove_one(std::vector<uint32_t>& list, uint32_t value) {
  auto it = std::find(list.begin(), list.end(), value);
  if (it != list.end()) {
    *it = list.back();
    list.pop_back();
  }
}

}  // namespace

void IncrementalAsa::reset() {
  ready_ = false;
  mid_pos_.clear();
  mid_refs_.clear();
  mid_edge_.clear();
  free_slots_.clear();
  mid_of_edge_.clear();
}

uint32_t IncrementalAsa::acquire_midpoint(uint32_t a, uint32_t b, const Vec3f& p, bool& conflict,
                                          std::vector<uint32_t>& touched) {
  const uint64_t key = edge_key(a, b);
  auto [it, inserted] = mid_of_edge_.try_emplace(key, 0u);
  uint32_t slot;
  if (inserted) {
    if (!free_slots_.empty()) {
      slot = free_slots_.back();
      free_slots_.pop_back();
    } else {
      slot = static_cast<uint32_t>(mid_pos_.size());
      mid_pos_.emplace_back();
      mid_refs_.push_back(0);
      mid_edge_.push_back(0);
    }
    it->second = slot;
    mid_pos_[slot] = p;
    mid_edge_[slot] = key;
    mid_refs_[slot] = 0;
  } else {
    slot = it->second;
    if (!same_bits(mid_pos_[slot], p)) conflict = true;
  }
  ++mid_refs_[slot];
  touched.push_back(slot);
  return slot;
}

void IncrementalAsa::release_children(uint32_t f, std::vector<uint32_t>& touched) {
  uint32_t slots[3];
  uint32_t n = 0;
  for (uint32_t i = 0; i < child_count_[f]; ++i) {
    for (uint32_t id : children_[4 * size_t(f) + i]) {
      if (!(id & kMid)) continue;
      const uint32_t s = id & ~kMid;
      if (std::find(slots, slots + n, s) == slots + n) slots[n++] = s;
    }
  }
  for (uint32_t k = 0; k < n; ++k) {
    const uint32_t s = slots[k];
    touched.push_back(s);
    if (--mid_refs_[s] == 0) {
      mid_of_edge_.erase(mid_edge_[s]);
      free_slots_.push_back(s);
    }
  }
  child_count_[f] = 0;
}

uint32_t IncrementalAsa::faces_on_edge(uint32_t a, uint32_t b) const {
  uint32_t n = 0;
  for (uint32_t f : star_[a]) {
    const Triangle& t = tris_[f];
    n += t[0] == b || t[1] == b || t[2] == b;
  }
  return n;
}

bool IncrementalAsa::adopt(const Mesh& mesh, const AsaOptions& options, const AsaResult& result) {
  reset();
  const uint32_t F = mesh.face_count(), V = mesh.vertex_count();
  tris_ = mesh.triangles;
  star_.resize(V);
  for (auto& s : star_) s.clear();
  for (uint32_t f = 0; f < F; ++f) {
    for (uint32_t v : tris_[f]) star_[v].push_back(f);
  }
  child_count_.assign(F, 0);
  kind_.assign(F, FaceKind::kUntouched);
  children_.resize(4 * size_t(F));
  face_mark_.assign(F, 0);
  epoch_ = 0;
  // Parse every face's children group.
  std::vector<uint32_t> touched;
  bool conflict = false;
  uint32_t cursor = 0;
  const auto& kinds = result.face_kind;
  const auto& out = result.mesh.triangles;
  for (uint32_t f = 0; f < F; ++f) {
    if (cursor >= kinds.size()) return false;
    const FaceKind k = kinds[cursor];
    const uint32_t n = group_size(k);
    if (n == 0 || cursor + n > kinds.size()) return false;
    for (uint32_t i = 0; i < n; ++i) {
      if (kinds[cursor + i] != k) return false;
    }
    // New vertices of the group and the edge each lies on.
    uint32_t news[3], count = 0;
    for (uint32_t i = 0; i < n; ++i) {
      for (uint32_t v : out[cursor + i]) {
        if (v >= V && std::find(news, news + count, v) == news + count) {
          if (count == 3) return false;
          news[count++] = v;
        }
      }
    }
    uint32_t slot_of[3];
    for (uint32_t j = 0; j < count; ++j) {
      uint32_t ends[3], e = 0;
      for (uint32_t i = 0; i < n; ++i) {
        const Triangle& t = out[cursor + i];
        if (t[0] != news[j] && t[1] != news[j] && t[2] != news[j]) continue;
        for (uint32_t v : t) {
          if (v < V && std::find(ends, ends + e, v) == ends + e) {
            if (e == 3) return false;
            ends[e++] = v;
          }
        }
      }
      if (n == 2 && e == 3) {
        // Bisected: the apex is in both halves; the split edge joins the others.
        uint32_t apex = kNoVertex;
        for (uint32_t v : out[cursor]) {
          const Triangle& t2 = out[cursor + 1];
          if (v < V && (t2[0] == v || t2[1] == v || t2[2] == v)) apex = v;
        }
        uint32_t k2 = 0;
        for (uint32_t q = 0; q < 3; ++q) {
          if (ends[q] != apex) ends[k2++] = ends[q];
        }
        e = k2;
      }
      if (e != 2) return false;
      slot_of[j] = acquire_midpoint(ends[0], ends[1], result.mesh.positions[news[j]], conflict, touched);
    }
    for (uint32_t i = 0; i < n; ++i) {
      Triangle t = out[cursor + i];
      for (uint32_t& v : t) {
        if (v >= V) v = kMid | slot_of[std::find(news, news + count, v) - news];
      }
      children_[4 * size_t(f) + i] = t;
    }
    child_count_[f] = static_cast<uint8_t>(n);
    kind_[f] = k;
    cursor += n;
  }
  if (conflict || cursor != kinds.size()) return false;
  (void)options;
  ready_ = true;
  return true;
}

void IncrementalAsa::sync_incidence(const Mesh& mesh, const MeshChanges& changes) {
  const uint32_t F = mesh.face_count(), V = mesh.vertex_count();
  const uint32_t old_f = static_cast<uint32_t>(tris_.size());
  if (star_.size() < V) star_.resize(V);
  if (F > old_f) {
    tris_.resize(F, Triangle{kNoVertex, kNoVertex, kNoVertex});
    child_count_.resize(F, 0);
    kind_.resize(F, FaceKind::kUntouched);
    children_.resize(4 * size_t(F));
    face_mark_.resize(F, 0);
  }
  for (uint32_t f : changes.faces) {
    const Triangle& now = mesh.triangles[f];
    Triangle& was = tris_[f];
    if (was == now) continue;
    if (was[0] != kNoVertex) {
      for (uint32_t v : was) remove_one(star_[v], f);
    }
    for (uint32_t v : now) star_[v].push_back(f);
    was = now;
  }
}

uint32_t IncrementalAsa::plan(const Mesh& mesh, const MeshChanges& changes, uint32_t limit) {
  region_.clear();
  region_dirty_ = 0;
  if (!ready_ || changes.full) return UINT32_MAX;
  sync_incidence(mesh, changes);
  if (++epoch_ == 0) {
    std::fill(face_mark_.begin(), face_mark_.end(), 0);
    epoch_ = 1;
  }
  for (uint32_t f : changes.faces) {
    if (face_mark_[f] != epoch_) {
      face_mark_[f] = epoch_;
      region_.push_back(f);
    }
  }
  size_t begin = 0;
  for (uint32_t ring = 0; ring < dirty_rings + context_rings; ++ring) {
    if (ring == dirty_rings) region_dirty_ = static_cast<uint32_t>(region_.size());
    const size_t end = region_.size();
    for (size_t i = begin; i < end; ++i) {
      for (uint32_t v : tris_[region_[i]]) {
        for (uint32_t g : star_[v]) {
          if (face_mark_[g] != epoch_) {
            face_mark_[g] = epoch_;
            region_.push_back(g);
          }
        }
      }
      if (region_.size() > limit) return UINT32_MAX;
    }
    begin = end;
  }
  if (dirty_rings + context_rings == 0 || region_dirty_ == 0) region_dirty_ = static_cast<uint32_t>(region_.size());
  return static_cast<uint32_t>(region_.size());
}

bool IncrementalAsa::update(const Mesh& mesh, const AsaOptions& options, AsaWorkspace& workspace) {
  if (!ready_ || region_.empty()) return ready_;
  // Cut out the region: dirty faces first, so their children come first.
  Mesh sub;
  std::vector<uint32_t> global;  // local vertex -> decoded vertex
  std::unordered_map<uint32_t, uint32_t> local;
  local.reserve(region_.size() * 2);
  sub.triangles.reserve(region_.size());
  for (uint32_t f : region_) {
    Triangle t = mesh.triangles[f];
    for (uint32_t& v : t) {
      auto [it, inserted] = local.try_emplace(v, static_cast<uint32_t>(global.size()));
      if (inserted) {
        global.push_back(v);
        sub.positions.push_back(mesh.positions[v]);
      }
      v = it->second;
    }
    sub.triangles.push_back(t);
  }
  last_region_faces = region_dirty_;
  last_submesh_faces = static_cast<uint32_t>(region_.size());
  AsaResult r;
  if (auto s = subdivide_into(sub, options, workspace, r); !s) {
    reset();
    return false;
  }
  const uint32_t SV = sub.vertex_count();
  std::vector<uint32_t> touched;
  for (uint32_t i = 0; i < region_dirty_; ++i) release_children(region_[i], touched);

  bool conflict = false;
  uint32_t cursor = 0;
  const auto& kinds = r.face_kind;
  const auto& out = r.mesh.triangles;
  for (uint32_t i = 0; i < region_dirty_ && !conflict; ++i) {
    const uint32_t f = region_[i];
    if (cursor >= kinds.size()) return reset(), false;
    const FaceKind k = kinds[cursor];
    const uint32_t n = group_size(k);
    if (n == 0 || cursor + n > kinds.size()) return reset(), false;
    uint32_t news[3], count = 0;
    for (uint32_t c = 0; c < n; ++c) {
      if (kinds[cursor + c] != k) return reset(), false;
      for (uint32_t v : out[cursor + c]) {
        if (v >= SV && std::find(news, news + count, v) == news + count) {
          if (count == 3) return reset(), false;
          news[count++] = v;
        }
      }
    }
    uint32_t slot_of[3];
    for (uint32_t j = 0; j < count; ++j) {
      uint32_t ends[3], e = 0;
      for (uint32_t c = 0; c < n; ++c) {
        const Triangle& t = out[cursor + c];
        if (t[0] != news[j] && t[1] != news[j] && t[2] != news[j]) continue;
        for (uint32_t v : t) {
          if (v < SV && std::find(ends, ends + e, v) == ends + e) {
            if (e == 3) return reset(), false;
            ends[e++] = v;
          }
        }
      }
      if (n == 2 && e == 3) {
        uint32_t apex = kNoVertex;
        for (uint32_t v : out[cursor]) {
          const Triangle& t2 = out[cursor + 1];
          if (v < SV && (t2[0] == v || t2[1] == v || t2[2] == v)) apex = v;
        }
        uint32_t k2 = 0;
        for (uint32_t q = 0; q < 3; ++q) {
          if (ends[q] != apex) ends[k2++] = ends[q];
        }
        e = k2;
      }
      if (e != 2) return reset(), false;
      slot_of[j] = acquire_midpoint(global[ends[0]], global[ends[1]], r.mesh.positions[news[j]], conflict, touched);
    }
    for (uint32_t c = 0; c < n; ++c) {
      Triangle t = out[cursor + c];
      for (uint32_t& v : t) {
        v = v >= SV ? kMid | slot_of[std::find(news, news + count, v) - news] : global[v];
      }
      children_[4 * size_t(f) + c] = t;
    }
    child_count_[f] = static_cast<uint8_t>(n);
    kind_[f] = k;
    cursor += n;
  }
  if (conflict) return reset(), false;
  // Both sides of every edge whose split state was touched must agree.
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  for (uint32_t s : touched) {
    if (mid_refs_[s] == 0) continue;
    const uint32_t a = static_cast<uint32_t>(mid_edge_[s] >> 32), b = static_cast<uint32_t>(mid_edge_[s]);
    if (mid_refs_[s] != faces_on_edge(a, b)) return reset(), false;
  }
  return true;
}

void IncrementalAsa::assemble(const Mesh& mesh, Mesh& out, std::vector<FaceKind>& kinds) const {
  const uint32_t F = mesh.face_count();
  out.positions.assign(mesh.positions.begin(), mesh.positions.end());
  out.triangles.clear();
  out.triangles.reserve(4 * size_t(F));
  out.normals.clear();
  out.colors.clear();
  out.texcoords.clear();
  kinds.clear();
  kinds.reserve(4 * size_t(F));
  std::vector<uint32_t> id(mid_pos_.size(), kNoVertex);
  for (uint32_t f = 0; f < F; ++f) {
    for (uint32_t i = 0; i < child_count_[f]; ++i) {
      Triangle t = children_[4 * size_t(f) + i];
      for (uint32_t& v : t) {
        if (!(v & kMid)) continue;
        const uint32_t s = v & ~kMid;
        if (id[s] == kNoVertex) {
          id[s] = static_cast<uint32_t>(out.positions.size());
          out.positions.push_back(mid_pos_[s]);
        }
        v = id[s];
      }
      out.triangles.push_back(t);
      kinds.push_back(kind_[f]);
    }
  }
}

}  // namespace meshstream::client
