// Incremental ASA: subdivide a region around what changed, prove the seam
// with the neighbouring patches, splice. See incremental.h.
#include "common/asa/incremental.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <numbers>
#include <optional>

#include "common/asa/flatness.h"
#include "common/asa/view.h"
#include "common/mesh/adjacency.h"

namespace meshstream {
namespace {

bool same_attribute_layout(const Mesh& a, const Mesh& b) {
  return a.colors.empty() == b.colors.empty() && a.texcoords.empty() == b.texcoords.empty() &&
         a.normals.empty() == b.normals.empty();
}

void compute_patch_starts(const std::vector<uint32_t>& source, uint32_t faces,
                          std::vector<uint32_t>& start) {
  start.assign(static_cast<size_t>(faces) + 1, 0);
  for (uint32_t s : source) ++start[s + 1];
  for (uint32_t f = 0; f < faces; ++f) start[f + 1] += start[f];
}

template <class T>
bool same_bits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

}  // namespace

IncrementalSubdivider::IncrementalSubdivider(const AsaOptions& options,
                                             const IncrementalOptions& incremental)
    : options_(options), incremental_(incremental) {
  options_.track_source_faces = true;
}

void IncrementalSubdivider::remember(const Mesh& input) {
  previous_.positions.assign(input.positions.begin(), input.positions.end());
  previous_.triangles.assign(input.triangles.begin(), input.triangles.end());
  previous_.colors.assign(input.colors.begin(), input.colors.end());
  previous_.texcoords.assign(input.texcoords.begin(), input.texcoords.end());
  previous_.normals.assign(input.normals.begin(), input.normals.end());
  adopt_canonical(input.vertex_count(), input.face_count());
  has_previous_ = true;
}

// result_ as subdivide() made it (patches contiguous, in input-face order,
// input vertices first) becomes the in-place layout: the patch lists, and
// the vertices renumbered with headroom for the input's growth. O(output).
void IncrementalSubdivider::adopt_canonical(uint32_t input_vertices, uint32_t input_faces) {
  const uint32_t F = result_.mesh.face_count();
  patch_first_.assign(input_faces, kNone);
  patch_size_.assign(input_faces, 0);
  patch_tail_.assign(input_faces, kNone);
  next_in_patch_.assign(F, kNone);
  for (uint32_t k = 0; k < F; ++k) {
    const uint32_t f = result_.source_face[k];
    if (patch_tail_[f] == kNone) {
      patch_first_[f] = k;
    } else {
      next_in_patch_[patch_tail_[f]] = k;
    }
    patch_tail_[f] = k;
    ++patch_size_[f];
  }
  input_slots_ = input_vertices;
  relayout(input_vertices + headroom_for(input_vertices));
}

// Slots kept free after the input's vertices for those later records add.
uint32_t IncrementalSubdivider::headroom_for(uint32_t input_vertices) const {
  return input_vertices / 8 + 1024;
}

// Renumbers the output vertices: [0, input_slots_) keep theirs (the input
// vertices' slots), [input_slots_, slots) become unused slots, and the
// vertices the faces use beyond them follow in first use; the free list
// empties. The faces keep their slots. O(output); a whole change.
void IncrementalSubdivider::relayout(uint32_t slots) {
  Mesh& out = result_.mesh;
  const uint32_t V = out.vertex_count(), keep = std::min(input_slots_, V);
  new_id_.assign(V, kNone);
  for (uint32_t v = 0; v < keep; ++v) new_id_[v] = v;
  uint32_t count = slots;
  for (Triangle& t : out.triangles)
    for (uint32_t& v : t) {
      if (new_id_[v] == kNone) new_id_[v] = count++;
      v = new_id_[v];
    }
  // (Positions always: an empty output still needs the input's slots.)
  auto remap = [&](auto& values, auto fill, bool always = false) {
    if (values.empty() && !always) return;
    std::remove_reference_t<decltype(values)> moved(count, fill);
    for (uint32_t v = 0; v < V; ++v)
      if (new_id_[v] != kNone) moved[new_id_[v]] = values[v];
    values.swap(moved);
  };
  remap(out.positions, V > 0 ? out.positions[0] : Vec3f{}, true);
  remap(out.colors, Vec4f{});
  remap(out.texcoords, Vec2f{});
  remap(out.normals, Vec3f{});
  vertex_refs_.assign(count, 0);
  for (const Triangle& t : out.triangles)
    for (uint32_t v : t) ++vertex_refs_[v];
  free_vertices_.clear();
  input_slots_ = slots;
  if (!log_.empty()) current_change().whole = true;
  stats_.rebuilt = true;
}

uint32_t IncrementalSubdivider::new_vertex_slot() {
  if (!free_vertices_.empty()) {
    const uint32_t v = free_vertices_.back();
    free_vertices_.pop_back();
    return v;
  }
  Mesh& out = result_.mesh;
  const uint32_t v = out.vertex_count();
  out.positions.emplace_back();
  if (!out.colors.empty()) out.colors.emplace_back();
  if (!out.texcoords.empty()) out.texcoords.emplace_back();
  vertex_refs_.push_back(0);
  return v;
}

void IncrementalSubdivider::release_vertex(uint32_t v) {
  if (--vertex_refs_[v] == 0 && v >= input_slots_) free_vertices_.push_back(v);
}

// Output face `from` (the last) moves to the free slot `to`; its patch list
// follows. O(patch).
void IncrementalSubdivider::move_face(uint32_t from, uint32_t to) {
  result_.mesh.triangles[to] = result_.mesh.triangles[from];
  result_.face_kind[to] = result_.face_kind[from];
  const uint32_t f = result_.source_face[to] = result_.source_face[from];
  next_in_patch_[to] = next_in_patch_[from];
  if (patch_first_[f] == from) {
    patch_first_[f] = to;
  } else {
    uint32_t k = patch_first_[f];
    while (next_in_patch_[k] != from) k = next_in_patch_[k];
    next_in_patch_[k] = to;
  }
  current_change().faces.push_back(to);
}

void IncrementalSubdivider::open_change() {
  static std::atomic<uint64_t> versions{0};
  version_ = ++versions;
  Change change;
  if (log_.size() == kLoggedChanges) {
    change = std::move(log_.front());  // (its memory)
    log_.pop_front();
  }
  change.version = version_;
  change.whole = false;
  change.faces.clear();
  change.vertices.clear();
  log_.push_back(std::move(change));
}

bool IncrementalSubdivider::copy_result_into(Mesh& mesh, std::vector<FaceKind>& kinds,
                                             uint64_t& version) const {
  if (version == version_ && version != 0) return true;
  size_t first = log_.size() + 1;  // the first change the copy lacks
  for (size_t i = 0; i < log_.size(); ++i)
    if (log_[i].version == version) first = i + 1;
  bool whole = version == 0 || first > log_.size();
  for (size_t i = first; !whole && i < log_.size(); ++i) whole = log_[i].whole;
  version = version_;
  const Mesh& r = result_.mesh;
  if (whole) {
    mesh = r;  // into the memory it had: no page faults
    kinds = result_.face_kind;
    return false;
  }
  // Every index whose value may differ from the copy's is listed in a
  // change since (slots beyond an array's old end are written when they
  // are taken): copying today's values at those indices suffices.
  mesh.positions.resize(r.positions.size());
  mesh.colors.resize(r.colors.size());
  mesh.texcoords.resize(r.texcoords.size());
  mesh.normals.resize(r.normals.size());
  mesh.triangles.resize(r.triangles.size());
  kinds.resize(result_.face_kind.size());
  const uint32_t V = r.vertex_count(), F = r.face_count();
  for (size_t i = first; i < log_.size(); ++i) {
    for (uint32_t v : log_[i].vertices) {
      if (v >= V) continue;
      mesh.positions[v] = r.positions[v];
      if (!r.colors.empty()) mesh.colors[v] = r.colors[v];
      if (!r.texcoords.empty()) mesh.texcoords[v] = r.texcoords[v];
    }
    for (uint32_t f : log_[i].faces) {
      if (f >= F) continue;
      mesh.triangles[f] = r.triangles[f];
      kinds[f] = result_.face_kind[f];
    }
  }
  return true;
}

AsaResult IncrementalSubdivider::canonical() const {
  AsaResult c;
  const Mesh& out = result_.mesh;
  const uint32_t Vn = std::min(previous_.vertex_count(), out.vertex_count());
  std::vector<uint32_t> id(out.vertex_count(), kNone);
  for (uint32_t v = 0; v < Vn; ++v) id[v] = v;
  auto first = [&](const auto& values, auto& into) {
    if (!values.empty()) into.assign(values.begin(), values.begin() + Vn);
  };
  first(out.positions, c.mesh.positions);
  first(out.colors, c.mesh.colors);
  first(out.texcoords, c.mesh.texcoords);
  first(out.normals, c.mesh.normals);
  for (uint32_t f = 0; f < patch_first_.size(); ++f)
    for (uint32_t k = patch_first_[f]; k != kNone; k = next_in_patch_[k]) {
      Triangle t = out.triangles[k];
      for (uint32_t& v : t) {
        if (id[v] == kNone) {
          id[v] = c.mesh.vertex_count();
          c.mesh.positions.push_back(out.positions[v]);
          if (!out.colors.empty()) c.mesh.colors.push_back(out.colors[v]);
          if (!out.texcoords.empty()) c.mesh.texcoords.push_back(out.texcoords[v]);
          if (!out.normals.empty()) c.mesh.normals.push_back(out.normals[v]);
        }
        v = id[v];
      }
      c.mesh.triangles.push_back(t);
      c.face_kind.push_back(result_.face_kind[k]);
      c.source_face.push_back(f);
    }
  return c;
}

// The level-0 adjacency, face normals and (with a camera) feature flags of
// `input`, from scratch. False when the mesh cannot have one (the caller's
// subdivision then reports why).
bool IncrementalSubdivider::rebuild_level0(const Mesh& input) {
  level0_valid_ = false;
  if (!table_.rebuild(input)) return false;
  const asa::LevelView view = level0(input);
  asa::compute_face_normals(view, face_normal_);
  changed_vertex_.assign(input.vertex_count(), 0);
  changed_list_.clear();
  bent_valid_ = false;
  if (options_.view.enabled && !options_.uniform) rebuild_bent(input);
  level0_valid_ = true;
  return true;
}

namespace {

// A corner's feature tag as asa::tag_feature_edges computes it (the same
// expression, so the same bits).
uint8_t feature_of(const std::vector<uint32_t>& opposite, const std::vector<Vec3f>& normals,
                   uint32_t c, bool creases, float cos_limit) {
  const uint32_t o = opposite[c];
  if (o == kNone) return 1;
  return creases && dot(normals[c / 3], normals[o / 3]) < cos_limit;
}

float crease_cosine(float crease_degrees) {
  return std::cos(crease_degrees * static_cast<float>(std::numbers::pi) / 180.0f);
}

}  // namespace

// Bits of face f's corners whose edges are bent, as asa::mark_targets
// tests them before asking the view.
uint8_t IncrementalSubdivider::bent_bits(uint32_t f) const {
  const std::vector<uint32_t>& opposite = table_.opposite();
  const Vec3f n = face_normal_[f];
  uint8_t bits = 0;
  for (uint32_t i = 0; i < 3; ++i) {
    const uint32_t c = 3 * f + i, o = opposite[c];
    if (o == kNone || feature_[c]) continue;
    if (dot(n, face_normal_[o / 3]) <= options_.flatness) bits |= uint8_t(1u << i);
  }
  return bits;
}

void IncrementalSubdivider::set_bent(uint32_t f, uint8_t bits) {
  bent_mask_[f] = bits;
  const uint32_t block = f / kBentBlock;
  if (block >= bent_blocks_.size()) bent_blocks_.resize(block + 1);
  if (!bent_blocks_[block].stale) {
    bent_blocks_[block].stale = true;
    stale_blocks_.push_back(block);
  }
}

void IncrementalSubdivider::refresh_bent_block(const Mesh& input, uint32_t block) {
  BentBlock& b = bent_blocks_[block];
  b = {};
  b.stale = false;
  const uint32_t first = block * kBentBlock;
  const uint32_t end = std::min<uint32_t>(first + kBentBlock, input.face_count());
  Vec3f lo{}, hi{};
  for (uint32_t f = first; f < end; ++f) {
    if (!bent_mask_[f]) continue;
    if (b.bent_faces == 0) lo = hi = input.positions[input.triangles[f][0]];
    for (uint32_t v : input.triangles[f]) {
      const Vec3f p = input.positions[v];
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    for (uint32_t i = 0; i < 3; ++i)
      if (bent_mask_[f] & (1u << i))
        b.longest = std::max(b.longest, length(input.positions[input.triangles[f][(i + 2) % 3]] -
                                               input.positions[input.triangles[f][(i + 1) % 3]]));
    ++b.bent_faces;
  }
  if (b.bent_faces == 0) return;
  b.centre = (lo + hi) * 0.5f;
  // Half the box's diagonal, a little over: every edge midpoint is inside the box.
  b.radius = 1.0001f * length(hi - lo) * 0.5f + 1e-6f * length(b.centre);
}

// From scratch: the feature tags and the bent faces. O(F).
void IncrementalSubdivider::rebuild_bent(const Mesh& input) {
  const uint32_t Fn = input.face_count();
  asa::tag_feature_edges(level0(input), options_.crease_degrees, face_normal_, feature_);
  bent_mask_.assign(Fn, 0);
  bent_blocks_.assign((Fn + kBentBlock - 1) / kBentBlock, BentBlock{});
  stale_blocks_.clear();
  for (uint32_t f = 0; f < Fn; ++f) bent_mask_[f] = bent_bits(f);
  for (uint32_t b = 0; b < bent_blocks_.size(); ++b) refresh_bent_block(input, b);
  bent_valid_ = true;
}

// After a record: the faces whose normals were recomputed (every face
// around a changed vertex, which includes every face whose corners or
// neighbours changed) get their feature tags again, mirrored to the
// corners across, and they and their neighbours their bent bits.
// O(refreshed faces).
void IncrementalSubdivider::refresh_bent(const Mesh& input) {
  const uint32_t Fn = input.face_count();
  const std::vector<uint32_t>& opposite = table_.opposite();
  const bool creases = options_.crease_degrees > 0;
  const float cos_limit = crease_cosine(options_.crease_degrees);
  feature_.resize(3 * static_cast<size_t>(Fn), 0);
  bent_mask_.resize(Fn, 0);
  for (uint32_t f : refreshed_faces_)
    for (uint32_t c = 3 * f; c < 3 * f + 3; ++c) {
      feature_[c] = feature_of(opposite, face_normal_, c, creases, cos_limit);
      if (opposite[c] != kNone) feature_[opposite[c]] = feature_[c];
    }
  for (uint32_t f : refreshed_faces_) {
    set_bent(f, bent_bits(f));
    for (uint32_t c = 3 * f; c < 3 * f + 3; ++c)
      if (opposite[c] != kNone) set_bent(opposite[c] / 3, bent_bits(opposite[c] / 3));
  }
}

asa::LevelView IncrementalSubdivider::level0(const Mesh& input) {
  asa::LevelView view;
  view.positions = input.positions.data();
  view.corner_vertex = input.triangles.empty() ? nullptr : input.triangles.front().data();
  view.opposite = table_.opposite().data();
  view.vertex_count = input.vertex_count();
  view.face_count = input.face_count();
  view.feature_edge = feature_.empty() ? nullptr : feature_.data();
  return view;
}

// With a camera, a "full" update need not subdivide the whole mesh: only
// the faces ASA targets (a bent edge that matters on screen; one pass over
// the faces with the level-0 adjacency) and the closure around them
// change. Taking the input itself (every face its own untouched patch) as
// the previous result, those targets are the change, and the region path
// below subdivides them with their rings and proves the seam. False when
// the region is most of the mesh or cannot be proven (the caller
// subdivides everything, which then costs about the same).
bool IncrementalSubdivider::view_region_update(const Mesh& input) {
  const uint32_t Fn = input.face_count();
  if (!validate_arrays(input)) return false;
  if (!ensure_level0(input)) return false;
  asa::LevelView view = level0(input);
  asa::tag_feature_edges(view, options_.crease_degrees, face_normal_, feature_);
  view.feature_edge = feature_.data();
  const asa::ViewTest test(options_.view);
  const uint32_t targets =
      asa::mark_targets(view, face_normal_, options_.flatness, target_after_, &test);
  if (4.0 * targets > Fn) return false;  // most of the mesh: the plain run is as fast
  for (uint32_t f = 0; f < Fn; ++f)
    if (target_after_[f])
      for (uint32_t v : input.triangles[f]) mark_vertex(v);
  result_.mesh.positions.assign(input.positions.begin(), input.positions.end());
  result_.mesh.triangles.assign(input.triangles.begin(), input.triangles.end());
  result_.mesh.colors.assign(input.colors.begin(), input.colors.end());
  result_.mesh.texcoords.assign(input.texcoords.begin(), input.texcoords.end());
  result_.mesh.normals.clear();
  result_.face_kind.assign(Fn, FaceKind::kUntouched);
  result_.source_face.resize(Fn);
  for (uint32_t f = 0; f < Fn; ++f) result_.source_face[f] = f;
  remember(input);
  if (targets == 0) {
    clear_vertex_marks();
    if (!input.normals.empty()) result_.mesh.normals = compute_vertex_normals(result_.mesh);
    return true;
  }
  for (uint32_t attempt = 0; attempt < incremental_.max_attempts; ++attempt) {
    stats_.attempts = attempt + 1;
    stats_.dirty_faces = grow_region(input, attempt);
    if (stats_.dirty_faces > incremental_.max_dirty_fraction * Fn) break;
    extract_region(input);
    stats_.region_faces = region_.face_count();
    if (!subdivide_into(region_, options_, workspace_, region_result_)) break;
    compute_patch_starts(region_result_.source_face, region_.face_count(), region_patch_start_);
    if (!seam_matches()) continue;
    splice(input);
    clear_vertex_marks();
    return true;
  }
  clear_vertex_marks();
  return false;
}

// The level-0 state (adjacency, face normals, bent bits) of `input`: kept
// when it is already up to date with it, else rebuilt. False as
// rebuild_level0.
bool IncrementalSubdivider::ensure_level0(const Mesh& input) {
  if (!level0_valid_) return rebuild_level0(input);
  if (options_.view.enabled && !options_.uniform && !bent_valid_) rebuild_bent(input);
  return true;
}

Status IncrementalSubdivider::full_update(const Mesh& input, bool level0_current) {
  // A region that grew too large leaves the level-0 state up to date with
  // `input` (the live table equals a rebuild, tests/client/live_adjacency_
  // test.cpp): keep it rather than rebuild the adjacency of the whole mesh.
  level0_valid_ = level0_valid_ && level0_current;
  clear_vertex_marks();
  if (!log_.empty()) current_change().whole = true;
  stats_.rebuilt = true;
  if (options_.view.enabled && !options_.uniform && options_.levels > 0) {
    stats_.full = false;
    if (view_region_update(input)) return {};
    stats_ = {};
  }
  stats_.full = true;
  stats_.dirty_faces = input.face_count();
  stats_.region_faces = input.face_count();
  auto done = subdivide_into(input, options_, workspace_, result_);
  if (!done) {
    has_previous_ = false;
    level0_valid_ = false;
    return done;
  }
  remember(input);
  ensure_level0(input);  // (view_region_update may have built it)
  return {};
}

void IncrementalSubdivider::mark_vertex(uint32_t v) {
  if (changed_vertex_[v]) return;
  changed_vertex_[v] = 1;
  changed_list_.push_back(v);
}

void IncrementalSubdivider::clear_vertex_marks() {
  for (uint32_t v : changed_list_) changed_vertex_[v] = 0;
  changed_list_.clear();
}

// 1. What changed, by comparing with the previous input: vertices moved or
// with new attributes, every vertex of a face that is new or re-connected,
// and those faces with their previous corners. O(V + F).
Status IncrementalSubdivider::collect_changes_by_diff(const Mesh& input) {
  if (auto ok = validate_arrays(input); !ok) return ok;
  const uint32_t Vn = input.vertex_count(), Fn = input.face_count();
  const uint32_t Vo = previous_.vertex_count(), Fo = previous_.face_count();
  changed_vertex_.resize(Vn, 0);
  changed_faces_.clear();
  old_corners_.clear();
  for (uint32_t v = 0; v < Vn; ++v) {
    const bool changed =
        v >= Vo || !same_bits(input.positions[v], previous_.positions[v]) ||
        (!input.colors.empty() && !same_bits(input.colors[v], previous_.colors[v])) ||
        (!input.texcoords.empty() && !same_bits(input.texcoords[v], previous_.texcoords[v]));
    if (changed) mark_vertex(v);
  }
  for (uint32_t f = 0; f < Fn; ++f) {
    if (f < Fo && input.triangles[f] == previous_.triangles[f]) continue;
    changed_faces_.push_back(f);
    old_corners_.push_back(f < Fo ? previous_.triangles[f] : Triangle{kNone, kNone, kNone});
    for (uint32_t v : input.triangles[f]) mark_vertex(v);
    if (f < Fo)
      for (uint32_t v : previous_.triangles[f]) mark_vertex(v);
  }
  return {};
}

// 1'. The same from the decoder's report: O(changes). The reported
// vertices and faces are checked as validate_arrays checks a whole mesh.
Status IncrementalSubdivider::collect_reported_changes(const Mesh& input,
                                                       const InputChanges& changes) {
  if (auto ok = check_attribute_counts(input); !ok) return ok;
  const uint32_t Vn = input.vertex_count(), Fn = input.face_count();
  const uint32_t Vo = previous_.vertex_count(), Fo = previous_.face_count();
  changed_vertex_.resize(Vn, 0);
  changed_faces_.clear();
  old_corners_.clear();
  auto vertex = [&](uint32_t v) -> Status {
    if (v >= Vn)
      return make_error(ErrorCode::kInvalidArgument, "changed vertex " + std::to_string(v) +
                                                         " is past the mesh's " +
                                                         std::to_string(Vn) + " vertices");
    const Vec3f& p = input.positions[v];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      return make_error(ErrorCode::kInvalidMesh, "vertex " + std::to_string(v) +
                                                     " has a non-finite coordinate (NaN or Inf)");
    mark_vertex(v);
    return {};
  };
  for (uint32_t v = Vo; v < Vn; ++v)
    if (auto ok = vertex(v); !ok) return ok;
  for (uint32_t v : changes.vertices)
    if (auto ok = vertex(v); !ok) return ok;
  for (uint32_t v : changes.moved)
    if (auto ok = vertex(v); !ok) return ok;
  face_seen_.resize(Fn, 0);
  next_generation(Fn, Vn);
  auto face = [&](uint32_t f) -> Status {
    if (f >= Fn)
      return make_error(ErrorCode::kInvalidArgument, "changed face " + std::to_string(f) +
                                                         " is past the mesh's " +
                                                         std::to_string(Fn) + " faces");
    if (face_seen_[f] == generation_) return {};
    face_seen_[f] = generation_;
    const Triangle& t = input.triangles[f];
    for (uint32_t v : t)
      if (v >= Vn)
        return make_error(ErrorCode::kInvalidMesh, "triangle " + std::to_string(f) +
                                                       " refers to vertex " + std::to_string(v) +
                                                       " but there are only " + std::to_string(Vn));
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0])
      return make_error(ErrorCode::kInvalidMesh,
                        "triangle " + std::to_string(f) + " repeats a vertex (degenerate)");
    changed_faces_.push_back(f);
    old_corners_.push_back(f < Fo ? previous_.triangles[f] : Triangle{kNone, kNone, kNone});
    for (uint32_t v : t) mark_vertex(v);
    if (f < Fo)
      for (uint32_t v : previous_.triangles[f]) mark_vertex(v);
    return {};
  };
  for (uint32_t f : changes.faces)
    if (auto ok = face(f); !ok) return ok;
  for (uint32_t f = Fo; f < Fn; ++f)
    if (auto ok = face(f); !ok) return ok;
  return {};
}

// previous_ becomes `input` by copying only what changed.
void IncrementalSubdivider::bring_previous_up_to_date(const Mesh& input) {
  const uint32_t Vn = input.vertex_count(), Fn = input.face_count();
  previous_.positions.resize(Vn);
  if (!input.colors.empty()) previous_.colors.resize(Vn);
  if (!input.texcoords.empty()) previous_.texcoords.resize(Vn);
  for (uint32_t v : changed_list_) {
    previous_.positions[v] = input.positions[v];
    if (!input.colors.empty()) previous_.colors[v] = input.colors[v];
    if (!input.texcoords.empty()) previous_.texcoords[v] = input.texcoords[v];
  }
  previous_.triangles.resize(Fn);
  for (uint32_t f : changed_faces_) previous_.triangles[f] = input.triangles[f];
}

// The normal of every face around a changed vertex, as
// asa::compute_face_normals computes it.
void IncrementalSubdivider::refresh_face_normals(const Mesh& input) {
  const uint32_t Fn = input.face_count();
  face_normal_.resize(Fn);
  face_seen_.resize(Fn, 0);
  next_generation(Fn, input.vertex_count());
  refreshed_faces_.clear();
  for (uint32_t v : changed_list_) {
    for (uint32_t f : table_.faces_around(v)) {
      if (face_seen_[f] == generation_) continue;
      face_seen_[f] = generation_;
      refreshed_faces_.push_back(f);
      const Triangle& t = input.triangles[f];
      const Vec3f p0 = input.positions[t[0]], p1 = input.positions[t[1]],
                  p2 = input.positions[t[2]];
      face_normal_[f] = normalized(cross(p1 - p0, p2 - p0));
    }
  }
}

void IncrementalSubdivider::next_generation(uint32_t faces, uint32_t vertices) {
  if (++generation_ == 0) {
    for (auto* a : {&dirty_stamp_, &region_stamp_, &face_seen_, &vertex_seen_, &local_stamp_})
      std::fill(a->begin(), a->end(), 0);
    generation_ = 1;
  }
  dirty_stamp_.resize(faces, 0);
  region_stamp_.resize(faces, 0);
  face_seen_.resize(faces, 0);
  vertex_seen_.resize(vertices, 0);
  local_stamp_.resize(vertices, 0);
}

// 3. Dirty faces: rings around the changed vertices; then context rings.
// Faces added in the first context ring are the clean neighbours whose
// patches prove the seam (seam_faces_). Returns the dirty face count.
// O(region): the rings walk the live adjacency.
uint32_t IncrementalSubdivider::grow_region(const Mesh& input, uint32_t attempt) {
  next_generation(input.face_count(), input.vertex_count());
  const uint32_t gen = generation_;
  frontier_.clear();
  region_faces_.clear();
  seam_faces_.clear();
  for (uint32_t v : changed_list_) {
    vertex_seen_[v] = gen;
    frontier_.push_back(v);
  }
  const uint32_t dirty_rings = incremental_.dirty_rings + attempt;
  const uint32_t context_rings = incremental_.context_rings + 2 * attempt;
  uint32_t dirty_count = 0;
  for (uint32_t ring = 0; ring < dirty_rings + context_rings; ++ring) {
    const bool dirty_ring = ring < dirty_rings;
    next_frontier_.clear();
    for (uint32_t v : frontier_) {
      for (uint32_t f : table_.faces_around(v)) {
        if (region_stamp_[f] == gen) continue;
        region_stamp_[f] = gen;
        region_faces_.push_back(f);
        if (dirty_ring) {
          dirty_stamp_[f] = gen;
          ++dirty_count;
        } else if (ring == dirty_rings) {
          seam_faces_.push_back(f);
        }
        for (uint32_t w : input.triangles[f])
          if (vertex_seen_[w] != gen) {
            vertex_seen_[w] = gen;
            next_frontier_.push_back(w);
          }
      }
    }
    frontier_.swap(next_frontier_);
  }
  close_region_fans(input);
  return dirty_count;
}

// The region must be a manifold mesh of its own: where the faces it holds
// around a vertex of its rim are not one contiguous fan (two blobs of the
// region touching at a vertex), the corner table of the region would
// refuse it. Such a vertex gets all its faces, as context; the faces added
// can pinch at their own vertices, so this repeats until none does. Only
// the last ring's vertices can have faces outside the region.
// O(rim x valence).
void IncrementalSubdivider::close_region_fans(const Mesh& input) {
  const uint32_t gen = generation_;
  auto in_region = [&](uint32_t f) { return region_stamp_[f] == gen; };
  // The region's faces around v form one contiguous run (or all of them).
  auto one_fan = [&](uint32_t v) {
    const std::vector<uint32_t>& around = table_.faces_around(v);
    uint32_t inside = 0, first = kNone;
    for (uint32_t f : around)
      if (in_region(f)) {
        ++inside;
        if (first == kNone) first = f;
      }
    if (inside == 0 || inside == around.size()) return true;
    return asa::faces_reached_around(input, table_.opposite().data(), v, first, around.size(),
                                     in_region) == inside;
  };
  std::vector<uint32_t>& work = frontier_;
  while (!work.empty()) {
    const uint32_t v = work.back();
    work.pop_back();
    if (one_fan(v)) continue;
    for (uint32_t f : table_.faces_around(v)) {
      if (in_region(f)) continue;
      region_stamp_[f] = gen;
      region_faces_.push_back(f);
      for (uint32_t w : input.triangles[f]) work.push_back(w);
    }
  }
}

// 4. The region as a mesh of its own (region_), faces in input order, with
// the maps between its indices and the input's. O(region log region).
void IncrementalSubdivider::extract_region(const Mesh& input) {
  const uint32_t gen = generation_;
  region_.positions.clear();
  region_.triangles.clear();
  region_.colors.clear();
  region_.texcoords.clear();
  local_vertex_.resize(input.vertex_count());
  local_face_.resize(input.face_count());
  global_vertex_.clear();
  std::sort(region_faces_.begin(), region_faces_.end());
  for (uint32_t f : region_faces_) {
    local_face_[f] = region_.face_count();
    Triangle t{};
    for (int i = 0; i < 3; ++i) {
      const uint32_t v = input.triangles[f][i];
      if (local_stamp_[v] != gen) {
        local_stamp_[v] = gen;
        local_vertex_[v] = static_cast<uint32_t>(global_vertex_.size());
        global_vertex_.push_back(v);
        region_.positions.push_back(input.positions[v]);
        if (!input.colors.empty()) region_.colors.push_back(input.colors[v]);
        if (!input.texcoords.empty()) region_.texcoords.push_back(input.texcoords[v]);
      }
      t[i] = local_vertex_[v];
    }
    region_.triangles.push_back(t);
  }
}

// 5. The clean neighbours' patches must come out of the region's run exactly
// as before; on the way, seam_map_ learns which previous output vertex each
// region output vertex on them is.
bool IncrementalSubdivider::seam_matches() {
  const Mesh& prev_out = result_.mesh;
  const Mesh& reg_out = region_result_.mesh;
  seam_map_.assign(reg_out.vertex_count(), kNone);
  for (uint32_t g : seam_faces_) {
    if (is_dirty(g)) continue;
    const uint32_t lg = local_face_[g];
    const uint32_t r0 = region_patch_start_[lg], r1 = region_patch_start_[lg + 1];
    if (patch_size_[g] != r1 - r0) return false;
    uint32_t k = patch_first_[g];
    for (uint32_t r = r0; r < r1; ++r, k = next_in_patch_[k]) {
      for (int i = 0; i < 3; ++i) {
        const uint32_t pv = prev_out.triangles[k][i], rv = reg_out.triangles[r][i];
        if (!same_bits(prev_out.positions[pv], reg_out.positions[rv]) ||
            (seam_map_[rv] != kNone && seam_map_[rv] != pv))
          return false;
        seam_map_[rv] = pv;
      }
    }
  }
  return true;
}

// 6. Splice in place: the dirty faces' old patches free their output faces
// and the vertices no other face uses; their new patches from the region
// take the freed faces first, then new ones at the end; freed faces left
// over are filled by the last faces. Kept vertices keep their slots, new
// ones take free slots first. Every write is logged for copy_result_into.
// O(region + patches moved).
void IncrementalSubdivider::splice(const Mesh& input) {
  const uint32_t Fn = input.face_count();
  Mesh& out = result_.mesh;
  const Mesh& reg_out = region_result_.mesh;
  Change& change = current_change();
  const bool colors = !input.colors.empty(), texcoords = !input.texcoords.empty();
  patch_first_.resize(Fn, kNone);
  patch_size_.resize(Fn, 0);
  free_faces_.clear();
  for (uint32_t f : region_faces_) {
    if (!is_dirty(f)) continue;
    for (uint32_t k = patch_first_[f]; k != kNone; k = next_in_patch_[k]) {
      free_faces_.push_back(k);
      for (uint32_t v : out.triangles[k]) release_vertex(v);
    }
    patch_first_[f] = kNone;
    patch_size_[f] = 0;
  }
  for (uint32_t v : changed_list_) {
    out.positions[v] = input.positions[v];
    if (colors) out.colors[v] = input.colors[v];
    if (texcoords) out.texcoords[v] = input.texcoords[v];
    change.vertices.push_back(v);
  }
  new_id_region_.assign(reg_out.vertex_count(), kNone);
  for (uint32_t x = 0; x < region_.vertex_count(); ++x) new_id_region_[x] = global_vertex_[x];
  auto take = [&](uint32_t x) {
    uint32_t id = new_id_region_[x];
    if (id == kNone) {
      if (seam_map_[x] != kNone) {
        id = seam_map_[x];
      } else {
        id = new_vertex_slot();
        out.positions[id] = reg_out.positions[x];
        if (colors) out.colors[id] = reg_out.colors[x];
        if (texcoords) out.texcoords[id] = reg_out.texcoords[x];
        change.vertices.push_back(id);
      }
      new_id_region_[x] = id;
    }
    ++vertex_refs_[id];
    return id;
  };
  size_t reused = 0;
  for (uint32_t f : region_faces_) {
    if (!is_dirty(f)) continue;
    const uint32_t lf = local_face_[f];
    uint32_t tail = kNone;
    for (uint32_t k = region_patch_start_[lf]; k < region_patch_start_[lf + 1]; ++k) {
      uint32_t slot;
      if (reused < free_faces_.size()) {
        slot = free_faces_[reused++];
      } else {
        slot = out.face_count();
        out.triangles.emplace_back();
        result_.face_kind.emplace_back();
        result_.source_face.push_back(f);
        next_in_patch_.push_back(kNone);
      }
      const Triangle& t = reg_out.triangles[k];
      out.triangles[slot] = {take(t[0]), take(t[1]), take(t[2])};
      result_.face_kind[slot] = region_result_.face_kind[k];
      result_.source_face[slot] = f;
      next_in_patch_[slot] = kNone;
      if (tail == kNone) {
        patch_first_[f] = slot;
      } else {
        next_in_patch_[tail] = slot;
      }
      tail = slot;
      ++patch_size_[f];
      change.faces.push_back(slot);
    }
  }
  if (reused < free_faces_.size()) {
    std::sort(free_faces_.begin() + static_cast<std::ptrdiff_t>(reused), free_faces_.end());
    size_t lo = reused, hi = free_faces_.size();
    uint32_t n = out.face_count();
    while (lo < hi) {
      if (free_faces_[hi - 1] == n - 1) {
        --hi;  // the last face is free itself
      } else {
        move_face(n - 1, free_faces_[lo++]);
      }
      --n;
    }
    out.triangles.resize(n);
    result_.face_kind.resize(n);
    result_.source_face.resize(n);
    next_in_patch_.resize(n);
  }
  if (!input.normals.empty()) {
    out.normals = compute_vertex_normals(out);
    change.whole = true;
  } else {
    out.normals.clear();
  }
  // Garbage bound: too many free vertex slots, renumber.
  if (free_vertices_.size() > 1024 + out.vertex_count() / 8) relayout(input_slots_);
}

namespace {
bool same_view(const AsaView& a, const AsaView& b) {
  return a.enabled == b.enabled && a.camera.eye == b.camera.eye &&
         a.camera.target == b.camera.target && a.camera.fov_degrees == b.camera.fov_degrees &&
         a.camera.width == b.camera.width && a.camera.height == b.camera.height &&
         a.pixel_tolerance == b.pixel_tolerance && a.frustum_margin == b.frustum_margin &&
         a.backface_margin == b.backface_margin && a.cull_back_faces == b.cull_back_faces &&
         a.facing_sign == b.facing_sign;
}
}  // namespace

void IncrementalSubdivider::set_view(const AsaView& view) {
  if (same_view(view, options_.view)) return;
  if (!view_changed_) previous_view_ = options_.view;
  options_.view = view;
  view_changed_ = true;
}

namespace {

// True when no edge inside face f's neighbourhood sphere can matter for
// `view`: the sphere (centroid, 1.5 x the farthest corner, plus half the
// longest edge for an edge's own sphere) is wholly outside the widened
// frustum or behind the eye, or even the longest edge at its nearest point
// projects to no more than the tolerance. Subdivision only shortens edges
// and moves new points a fraction of an edge off the face, so what holds
// for the sphere holds for every descendant edge.
class QuietFaces {
 public:
  explicit QuietFaces(const AsaView& view) : view_(view) {
    const AsaCamera& c = view.camera;
    eye_ = c.eye;
    forward_ = normalized(c.target - c.eye);
    Vec3f world_up{0, 1, 0};
    if (std::fabs(forward_.y) > 0.999f) world_up = {0, 0, 1};
    right_ = normalized(cross(forward_, world_up));
    up_ = cross(right_, forward_);
    const float aspect = static_cast<float>(c.width) / static_cast<float>(std::max(c.height, 1));
    const float tan_half = std::tan(c.fov_degrees * 3.14159265f / 360.0f);
    tan_y_ = tan_half * (1 + view.frustum_margin);
    tan_x_ = tan_half * aspect * (1 + view.frustum_margin);
    inv_x_ = 1.0f / std::sqrt(1 + tan_x_ * tan_x_);
    inv_y_ = 1.0f / std::sqrt(1 + tan_y_ * tan_y_);
    focal_px_ = static_cast<float>(c.height) / (2 * tan_half);
  }

  bool quiet(Vec3f a, Vec3f b, Vec3f c) const {
    if (!view_.enabled) return false;
    const Vec3f centre = (a + b + c) / 3.0f;
    const float corner = std::sqrt(std::max(
        {squared_length(a - centre), squared_length(b - centre), squared_length(c - centre)}));
    const float longest =
        std::sqrt(std::max({squared_length(b - a), squared_length(c - b), squared_length(a - c)}));
    const float r = 1.5f * corner + 0.5f * longest;
    const Vec3f rel = centre - eye_;
    const float dist = length(rel);
    if (dist <= r) return false;
    if (longest * focal_px_ <= view_.pixel_tolerance * (dist - r)) return true;
    const float z = dot(rel, forward_), x = dot(rel, right_), y = dot(rel, up_);
    if (z < -r) return true;
    if ((std::fabs(x) - z * tan_x_) * inv_x_ > r) return true;
    if ((std::fabs(y) - z * tan_y_) * inv_y_ > r) return true;
    return false;
  }

 private:
  const AsaView& view_;
  Vec3f eye_, forward_, right_, up_;
  float tan_x_ = 1, tan_y_ = 1, inv_x_ = 1, inv_y_ = 1, focal_px_ = 1;
};

}  // namespace

// 1b. After set_view: the vertices of every input face whose level-0 ASA
// target flag differs between the two views count as changed; with more
// levels, also those of faces refined in either view that are not wholly
// quiet for both (their descendants' verdicts may differ). Returns the
// number of such faces. Two target passes over the faces (flatness first,
// the view only for bent edges) and one sphere test per refined face.
uint32_t IncrementalSubdivider::mark_view_changes(const Mesh& input) {
  if (bent_valid_ && options_.levels == 1) return mark_view_changes_of_bent_faces(input);
  const uint32_t Fn = input.face_count();
  asa::LevelView view = level0(input);
  asa::tag_feature_edges(view, options_.crease_degrees, face_normal_, feature_);
  view.feature_edge = feature_.data();
  const asa::ViewTest test_after(options_.view);
  asa::mark_targets(view, face_normal_, options_.flatness, target_after_, &test_after);
  if (previous_view_.enabled) {
    const asa::ViewTest test_before(previous_view_);
    asa::mark_targets(view, face_normal_, options_.flatness, target_before_, &test_before);
  } else {
    asa::mark_targets(view, face_normal_, options_.flatness, target_before_, nullptr);
  }
  const bool deeper = options_.levels > 1;
  const QuietFaces before(previous_view_), after(options_.view);
  const uint32_t patched = static_cast<uint32_t>(patch_size_.size());
  uint32_t faces = 0;
  for (uint32_t f = 0; f < Fn; ++f) {
    bool redo = target_before_[f] != target_after_[f];
    if (!redo && deeper) {
      const bool refined = target_after_[f] || f >= patched || patch_size_[f] > 1;
      if (refined) {
        const Triangle& t = input.triangles[f];
        const Vec3f a = input.positions[t[0]], b = input.positions[t[1]], c = input.positions[t[2]];
        redo = !(before.quiet(a, b, c) && after.quiet(a, b, c));
      }
    }
    if (!redo) continue;
    ++faces;
    for (uint32_t v : input.triangles[f]) mark_vertex(v);
  }
  return faces;
}

// 1b with one level: only a face with a bent edge can be a target in
// either view, so only those are asked, with the same test as
// asa::mark_targets. O(bent faces).
uint32_t IncrementalSubdivider::mark_view_changes_of_bent_faces(const Mesh& input) {
  const std::vector<uint32_t>& opposite = table_.opposite();
  const asa::ViewTest test_after(options_.view);
  const std::optional<asa::ViewTest> test_before =
      previous_view_.enabled ? std::optional<asa::ViewTest>(previous_view_) : std::nullopt;
  auto target = [&](uint32_t f, const asa::ViewTest* test) {
    const uint8_t bits = bent_mask_[f];
    if (test == nullptr) return bits != 0;
    for (uint32_t i = 0; i < 3; ++i) {
      if (!(bits & (1u << i))) continue;
      const uint32_t c = 3 * f + i;
      const Vec3f a = input.positions[input.triangles[f][(i + 1) % 3]];
      const Vec3f b = input.positions[input.triangles[f][(i + 2) % 3]];
      if (test->matters(a, b, face_normal_[f], face_normal_[opposite[c] / 3])) return true;
    }
    return false;
  };
  for (uint32_t b : stale_blocks_) refresh_bent_block(input, b);
  stale_blocks_.clear();
  const uint32_t Fn = input.face_count();
  uint32_t faces = 0;
  for (uint32_t b = 0; b < bent_blocks_.size(); ++b) {
    const BentBlock& block = bent_blocks_[b];
    if (block.bent_faces == 0) continue;
    // No edge of the block matters in either view: no target flips.
    if (test_before && !test_before->may_matter(block.centre, block.radius, block.longest) &&
        !test_after.may_matter(block.centre, block.radius, block.longest))
      continue;
    const uint32_t end = std::min<uint32_t>((b + 1) * kBentBlock, Fn);
    for (uint32_t f = b * kBentBlock; f < end; ++f) {
      if (!bent_mask_[f]) continue;
      if (target(f, test_before ? &*test_before : nullptr) == target(f, &test_after)) continue;
      ++faces;
      for (uint32_t v : input.triangles[f]) mark_vertex(v);
    }
  }
  return faces;
}

Status IncrementalSubdivider::update(const Mesh& input, const InputChanges* changes) {
  stats_ = {};
  open_change();
  const bool view_changed = view_changed_;
  view_changed_ = false;
  if (view_changed && has_previous_ && previous_view_.enabled != options_.view.enabled)
    return full_update(input);  // every decision may change
  if (!has_previous_ || !level0_valid_ || options_.levels == 0 ||
      !same_attribute_layout(input, previous_) || input.vertex_count() < previous_.vertex_count() ||
      input.face_count() < previous_.face_count()) {
    return full_update(input);
  }
  if (auto ok =
          changes ? collect_reported_changes(input, *changes) : collect_changes_by_diff(input);
      !ok) {
    clear_vertex_marks();
    has_previous_ = false;
    return ok;
  }
  if (!table_.apply(input, changed_faces_, old_corners_)) {
    return full_update(input);  // reports the problem (non-manifold) with the whole mesh's view
  }
  bring_previous_up_to_date(input);
  refresh_face_normals(input);
  if (bent_valid_) refresh_bent(input);
  if (view_changed && options_.view.enabled && !options_.uniform)
    stats_.view_faces = mark_view_changes(input);
  stats_.changed_vertices = static_cast<uint32_t>(changed_list_.size());
  const uint32_t Fn = input.face_count();
  if (changed_list_.empty() && Fn == patch_size_.size()) return {};
  // New input vertices need their slots (input vertex i is output vertex i).
  if (input.vertex_count() > input_slots_)
    relayout(input.vertex_count() + headroom_for(input.vertex_count()));
  for (uint32_t attempt = 0; attempt < incremental_.max_attempts; ++attempt) {
    stats_.attempts = attempt + 1;
    stats_.dirty_faces = grow_region(input, attempt);
    if (stats_.dirty_faces > incremental_.max_dirty_fraction * Fn)
      return full_update(input, /*level0_current=*/true);
    extract_region(input);
    stats_.region_faces = region_.face_count();
    if (!subdivide_into(region_, options_, workspace_, region_result_)) {
      return full_update(input);  // reports the error with global indices
    }
    compute_patch_starts(region_result_.source_face, region_.face_count(), region_patch_start_);
    if (!seam_matches()) continue;  // the closure reached further: grow the region
    splice(input);
    clear_vertex_marks();
    return {};
  }
  return full_update(input, /*level0_current=*/true);
}

}  // namespace meshstream
