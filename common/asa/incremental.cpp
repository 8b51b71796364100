// Incremental ASA: subdivide a region around what changed, prove the seam
// with the neighbouring patches, splice. See incremental.h.
#include "common/asa/incremental.h"

#include <algorithm>
#include <cmath>
#include <cstring>

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
  compute_patch_starts(result_.source_face, input.face_count(), patch_start_);
  has_previous_ = true;
}

// With a camera, a "full" update need not subdivide the whole mesh: faces
// none of whose edges can matter on screen are not targets by themselves.
// Taking the input itself (every face its own untouched patch) as the
// previous result, the faces that may matter are the change, and the region
// path below subdivides them with their rings and proves the seam. False
// when the region would be most of the mesh or cannot be proven (the caller
// subdivides everything).
bool IncrementalSubdivider::view_region_update(const Mesh& input) {
  const uint32_t Vn = input.vertex_count(), Fn = input.face_count();
  if (!validate_arrays(input)) return false;
  const asa::ViewTest test(options_.view);
  changed_vertex_.assign(Vn, 0);
  uint32_t candidates = 0;
  for (const Triangle& t : input.triangles) {
    const Vec3f a = input.positions[t[0]], b = input.positions[t[1]], c = input.positions[t[2]];
    const Vec3f n = normalized(cross(b - a, c - a));
    if (!test.matters(a, b, n, n) && !test.matters(b, c, n, n) && !test.matters(c, a, n, n))
      continue;
    ++candidates;
    for (uint32_t v : t) changed_vertex_[v] = 1;
  }
  // The region is the candidates grown by several rings: give up early
  // where that is bound to be most of the mesh.
  if (4.0 * candidates > incremental_.max_dirty_fraction * Fn) return false;
  result_.mesh.positions.assign(input.positions.begin(), input.positions.end());
  result_.mesh.triangles.assign(input.triangles.begin(), input.triangles.end());
  result_.mesh.colors.assign(input.colors.begin(), input.colors.end());
  result_.mesh.texcoords.assign(input.texcoords.begin(), input.texcoords.end());
  result_.mesh.normals.clear();
  result_.face_kind.assign(Fn, FaceKind::kUntouched);
  result_.source_face.resize(Fn);
  for (uint32_t f = 0; f < Fn; ++f) result_.source_face[f] = f;
  remember(input);
  if (candidates == 0) {
    if (!input.normals.empty()) result_.mesh.normals = compute_vertex_normals(result_.mesh);
    return true;
  }
  index_vertex_faces(input);
  for (uint32_t attempt = 0; attempt < incremental_.max_attempts; ++attempt) {
    stats_.attempts = attempt + 1;
    stats_.dirty_faces = grow_region(input, attempt);
    if (stats_.dirty_faces > incremental_.max_dirty_fraction * Fn) return false;
    extract_region(input);
    stats_.region_faces = region_.face_count();
    if (!subdivide_into(region_, options_, workspace_, region_result_)) return false;
    compute_patch_starts(region_result_.source_face, region_.face_count(), region_patch_start_);
    if (!seam_matches()) continue;
    splice(input);
    std::swap(result_, next_);
    remember(input);
    return true;
  }
  return false;
}

Status IncrementalSubdivider::full_update(const Mesh& input) {
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
    return done;
  }
  remember(input);
  return {};
}

// 1. What changed, by index: vertices moved or with new attributes, and every
// vertex of a face that is new, gone or re-connected. Returns their count.
uint32_t IncrementalSubdivider::mark_changed_vertices(const Mesh& input) {
  const uint32_t Vn = input.vertex_count(), Fn = input.face_count();
  const uint32_t Vo = previous_.vertex_count(), Fo = previous_.face_count();
  changed_vertex_.assign(Vn, 0);
  for (uint32_t v = 0; v < Vn; ++v) {
    bool changed =
        v >= Vo || !same_bits(input.positions[v], previous_.positions[v]) ||
        (!input.colors.empty() && !same_bits(input.colors[v], previous_.colors[v])) ||
        (!input.texcoords.empty() && !same_bits(input.texcoords[v], previous_.texcoords[v]));
    changed_vertex_[v] = changed;
  }
  auto mark = [&](const Triangle& t) {
    for (uint32_t v : t)
      if (v < Vn) changed_vertex_[v] = 1;
  };
  for (uint32_t f = 0; f < Fn; ++f) {
    if (f < Fo && input.triangles[f] == previous_.triangles[f]) continue;
    mark(input.triangles[f]);
    if (f < Fo) mark(previous_.triangles[f]);
  }
  for (uint32_t f = Fn; f < Fo; ++f) mark(previous_.triangles[f]);
  uint32_t changed = 0;
  for (uint8_t c : changed_vertex_) changed += c;
  return changed;
}

// 2. Faces around every vertex of the new input (CSR).
void IncrementalSubdivider::index_vertex_faces(const Mesh& input) {
  const uint32_t Vn = input.vertex_count(), Fn = input.face_count();
  vertex_faces_offset_.assign(static_cast<size_t>(Vn) + 1, 0);
  for (const Triangle& t : input.triangles)
    for (uint32_t v : t) ++vertex_faces_offset_[v + 1];
  for (uint32_t v = 0; v < Vn; ++v) vertex_faces_offset_[v + 1] += vertex_faces_offset_[v];
  vertex_faces_.resize(3 * static_cast<size_t>(Fn));
  std::vector<uint32_t>& cursor = global_vertex_;  // borrowed as a fill cursor
  cursor.assign(vertex_faces_offset_.begin(), vertex_faces_offset_.end() - 1);
  for (uint32_t f = 0; f < Fn; ++f)
    for (uint32_t v : input.triangles[f]) vertex_faces_[cursor[v]++] = f;
}

// 3. Dirty faces: rings around the changed vertices; then context rings.
// Faces added in the first context ring are the clean neighbours whose
// patches prove the seam (seam_faces_). Returns the dirty face count.
uint32_t IncrementalSubdivider::grow_region(const Mesh& input, uint32_t attempt) {
  const uint32_t Vn = input.vertex_count(), Fn = input.face_count();
  dirty_face_.assign(Fn, 0);
  in_region_.assign(Fn, 0);
  vertex_mark_.assign(Vn, 0);
  frontier_.clear();
  seam_faces_.clear();
  for (uint32_t v = 0; v < Vn; ++v)
    if (changed_vertex_[v]) {
      vertex_mark_[v] = 1;
      frontier_.push_back(v);
    }
  const uint32_t dirty_rings = incremental_.dirty_rings + attempt;
  const uint32_t context_rings = incremental_.context_rings + 2 * attempt;
  uint32_t dirty_count = 0;
  for (uint32_t ring = 0; ring < dirty_rings + context_rings; ++ring) {
    const bool dirty_ring = ring < dirty_rings;
    next_frontier_.clear();
    for (uint32_t v : frontier_) {
      for (uint32_t k = vertex_faces_offset_[v]; k < vertex_faces_offset_[v + 1]; ++k) {
        const uint32_t f = vertex_faces_[k];
        if (in_region_[f]) continue;
        in_region_[f] = 1;
        if (dirty_ring) {
          dirty_face_[f] = 1;
          ++dirty_count;
        } else if (ring == dirty_rings) {
          seam_faces_.push_back(f);
        }
        for (uint32_t w : input.triangles[f])
          if (!vertex_mark_[w]) {
            vertex_mark_[w] = 1;
            next_frontier_.push_back(w);
          }
      }
    }
    frontier_.swap(next_frontier_);
  }
  return dirty_count;
}

// 4. The region as a mesh of its own (region_), faces in input order, with
// the maps between its indices and the input's.
void IncrementalSubdivider::extract_region(const Mesh& input) {
  const uint32_t Vn = input.vertex_count(), Fn = input.face_count();
  region_.positions.clear();
  region_.triangles.clear();
  region_.colors.clear();
  region_.texcoords.clear();
  local_vertex_.assign(Vn, kNone);
  local_face_.assign(Fn, kNone);
  global_vertex_.clear();
  region_faces_.clear();
  for (uint32_t f = 0; f < Fn; ++f) {
    if (!in_region_[f]) continue;
    local_face_[f] = static_cast<uint32_t>(region_faces_.size());
    region_faces_.push_back(f);
    Triangle t{};
    for (int i = 0; i < 3; ++i) {
      const uint32_t v = input.triangles[f][i];
      if (local_vertex_[v] == kNone) {
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
    if (dirty_face_[g]) continue;
    const uint32_t lg = local_face_[g];
    const uint32_t p0 = patch_start_[g], p1 = patch_start_[g + 1];
    const uint32_t r0 = region_patch_start_[lg], r1 = region_patch_start_[lg + 1];
    if (p1 - p0 != r1 - r0) return false;
    for (uint32_t k = 0; k < p1 - p0; ++k) {
      for (int i = 0; i < 3; ++i) {
        const uint32_t pv = prev_out.triangles[p0 + k][i], rv = reg_out.triangles[r0 + k][i];
        if (!same_bits(prev_out.positions[pv], reg_out.positions[rv]) ||
            (seam_map_[rv] != kNone && seam_map_[rv] != pv))
          return false;
        seam_map_[rv] = pv;
      }
    }
  }
  return true;
}

// 6. Splice into next_: clean patches from the previous result, dirty ones
// from the region; input vertices first, then others as first used.
void IncrementalSubdivider::splice(const Mesh& input) {
  const uint32_t Fn = input.face_count(), Vo = previous_.vertex_count();
  const Mesh& prev_out = result_.mesh;
  const Mesh& reg_out = region_result_.mesh;
  new_id_prev_.assign(prev_out.vertex_count(), kNone);
  for (uint32_t v = 0; v < Vo; ++v) new_id_prev_[v] = v;
  new_id_region_.assign(reg_out.vertex_count(), kNone);
  for (uint32_t x = 0; x < region_.vertex_count(); ++x) new_id_region_[x] = global_vertex_[x];
  Mesh& out = next_.mesh;
  out.positions.assign(input.positions.begin(), input.positions.end());
  out.colors.assign(input.colors.begin(), input.colors.end());
  out.texcoords.assign(input.texcoords.begin(), input.texcoords.end());
  out.triangles.clear();
  next_.face_kind.clear();
  next_.source_face.clear();
  const bool colors = !input.colors.empty(), texcoords = !input.texcoords.empty();
  auto take_prev = [&](uint32_t p) {
    uint32_t& id = new_id_prev_[p];
    if (id == kNone) {
      id = static_cast<uint32_t>(out.positions.size());
      out.positions.push_back(prev_out.positions[p]);
      if (colors) out.colors.push_back(prev_out.colors[p]);
      if (texcoords) out.texcoords.push_back(prev_out.texcoords[p]);
    }
    return id;
  };
  auto take_region = [&](uint32_t x) {
    uint32_t& id = new_id_region_[x];
    if (id == kNone) {
      if (seam_map_[x] != kNone) {
        id = take_prev(seam_map_[x]);
      } else {
        id = static_cast<uint32_t>(out.positions.size());
        out.positions.push_back(reg_out.positions[x]);
        if (colors) out.colors.push_back(reg_out.colors[x]);
        if (texcoords) out.texcoords.push_back(reg_out.texcoords[x]);
      }
    }
    return id;
  };
  for (uint32_t f = 0; f < Fn; ++f) {
    if (dirty_face_[f]) {
      const uint32_t lf = local_face_[f];
      for (uint32_t k = region_patch_start_[lf]; k < region_patch_start_[lf + 1]; ++k) {
        const Triangle& t = reg_out.triangles[k];
        out.triangles.push_back({take_region(t[0]), take_region(t[1]), take_region(t[2])});
        next_.face_kind.push_back(region_result_.face_kind[k]);
        next_.source_face.push_back(f);
      }
    } else {
      for (uint32_t k = patch_start_[f]; k < patch_start_[f + 1]; ++k) {
        const Triangle& t = prev_out.triangles[k];
        out.triangles.push_back({take_prev(t[0]), take_prev(t[1]), take_prev(t[2])});
        next_.face_kind.push_back(result_.face_kind[k]);
        next_.source_face.push_back(f);
      }
    }
  }
  if (!input.normals.empty()) {
    out.normals = compute_vertex_normals(out);
  } else {
    out.normals.clear();
  }
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

// 1b. After set_view: every vertex of an input face that either view may
// refine counts as changed. Returns the number of such faces.
uint32_t IncrementalSubdivider::mark_view_changes(const Mesh& input) {
  const QuietFaces before(previous_view_), after(options_.view);
  uint32_t faces = 0;
  for (const Triangle& t : input.triangles) {
    const Vec3f a = input.positions[t[0]], b = input.positions[t[1]], c = input.positions[t[2]];
    if (before.quiet(a, b, c) && after.quiet(a, b, c)) continue;
    ++faces;
    for (uint32_t v : t) changed_vertex_[v] = 1;
  }
  return faces;
}

Status IncrementalSubdivider::update(const Mesh& input) {
  stats_ = {};
  const bool view_changed = view_changed_;
  view_changed_ = false;
  if (view_changed && has_previous_ && previous_view_.enabled != options_.view.enabled)
    return full_update(input);  // every decision may change
  if (!has_previous_ || options_.levels == 0 || !same_attribute_layout(input, previous_) ||
      input.vertex_count() < previous_.vertex_count()) {
    return full_update(input);
  }
  if (auto ok = validate_arrays(input); !ok) {
    has_previous_ = false;
    return ok;
  }
  stats_.changed_vertices = mark_changed_vertices(input);
  if (view_changed) {
    stats_.view_faces = mark_view_changes(input);
    stats_.changed_vertices = 0;
    for (uint8_t c : changed_vertex_) stats_.changed_vertices += c;
  }
  if (stats_.changed_vertices == 0 && input.face_count() == previous_.face_count()) {
    if (!input.normals.empty()) previous_.normals = input.normals;
    return {};
  }
  index_vertex_faces(input);
  for (uint32_t attempt = 0; attempt < incremental_.max_attempts; ++attempt) {
    stats_.attempts = attempt + 1;
    stats_.dirty_faces = grow_region(input, attempt);
    if (stats_.dirty_faces > incremental_.max_dirty_fraction * input.face_count())
      return full_update(input);
    extract_region(input);
    stats_.region_faces = region_.face_count();
    if (!subdivide_into(region_, options_, workspace_, region_result_)) {
      return full_update(input);  // reports the error with global indices
    }
    compute_patch_starts(region_result_.source_face, region_.face_count(), region_patch_start_);
    if (!seam_matches()) continue;  // the closure reached further: grow the region
    splice(input);
    std::swap(result_, next_);
    remember(input);
    return {};
  }
  return full_update(input);
}

}  // namespace meshstream
