// Frustum and hidden back-face culling of a display mesh; see display_cull.h
// for why the picture cannot change.
#include "common/asa/display_cull.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace meshstream {
namespace {

constexpr float kDegrees = static_cast<float>(std::numbers::pi) / 180.0f;
// The widened cone stays a cone (a half-angle near 90 degrees would put
// the apex at infinity).
constexpr float kMaxHalfAngle = 85.0f * kDegrees;

uint64_t mix(uint64_t x) {  // splitmix64's finalizer
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// A directed edge's term: the sum over a component is zero when every edge
// is used as often a -> b as b -> a (a closed, consistently oriented surface).
uint64_t directed(uint32_t a, uint32_t b) {
  return mix((uint64_t(a) << 32) | b) - mix((uint64_t(b) << 32) | a);
}

uint32_t find(std::vector<uint32_t>& parent, uint32_t v) {
  while (parent[v] != v) {
    parent[v] = parent[parent[v]];
    v = parent[v];
  }
  return v;
}

float distance_to_box(Vec3f p, const BoundingBox& b) {
  const float dx = std::max({b.min.x - p.x, 0.0f, p.x - b.max.x});
  const float dy = std::max({b.min.y - p.y, 0.0f, p.y - b.max.y});
  const float dz = std::max({b.min.z - p.z, 0.0f, p.z - b.max.z});
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// Half-angle of the cone around the view axis through the image corners.
float corner_half_angle(const AsaCamera& c) {
  const float aspect = float(std::max(c.width, 1)) / float(std::max(c.height, 1));
  const float t = std::tan(c.fov_degrees * kDegrees / 2);
  return std::atan(t * std::sqrt(1 + aspect * aspect));
}

}  // namespace

std::shared_ptr<const DisplayTopology> analyze_display_topology(const Mesh& mesh) {
  auto topo = std::make_shared<DisplayTopology>();
  const uint32_t V = mesh.vertex_count(), F = mesh.face_count();
  std::vector<uint32_t> parent(V);
  for (uint32_t v = 0; v < V; ++v) parent[v] = v;
  for (const Triangle& t : mesh.triangles) {
    for (int k = 1; k < 3; ++k) {
      const uint32_t a = find(parent, t[0]), b = find(parent, t[k]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  // Components numbered by their smallest vertex.
  std::vector<uint32_t> component(V, DisplayTopology::kOpen);
  uint32_t count = 0;
  for (uint32_t v = 0; v < V; ++v) {
    const uint32_t root = find(parent, v);
    if (component[root] == DisplayTopology::kOpen) component[root] = count++;
    component[v] = component[root];
  }
  struct Facts {
    BoundingBox box{{1e30f, 1e30f, 1e30f}, {-1e30f, -1e30f, -1e30f}};
    double volume = 0;
    uint64_t balance = 0;
  };
  std::vector<Facts> facts(count);
  for (uint32_t v = 0; v < V; ++v) {
    BoundingBox& b = facts[component[v]].box;
    const Vec3f p = mesh.positions[v];
    b.min = {std::min(b.min.x, p.x), std::min(b.min.y, p.y), std::min(b.min.z, p.z)};
    b.max = {std::max(b.max.x, p.x), std::max(b.max.y, p.y), std::max(b.max.z, p.z)};
  }
  const BoundingBox all = bounding_box(mesh);
  const Vec3f o = (all.min + all.max) * 0.5f;
  topo->face_component.resize(F);
  for (uint32_t f = 0; f < F; ++f) {
    const Triangle& t = mesh.triangles[f];
    Facts& c = facts[component[t[0]]];
    const Vec3f a = mesh.positions[t[0]] - o, b = mesh.positions[t[1]] - o,
                d = mesh.positions[t[2]] - o;
    c.volume += double(a.x) * (double(b.y) * d.z - double(b.z) * d.y) +
                double(a.y) * (double(b.z) * d.x - double(b.x) * d.z) +
                double(a.z) * (double(b.x) * d.y - double(b.y) * d.x);
    c.balance += directed(t[0], t[1]) + directed(t[1], t[2]) + directed(t[2], t[0]);
    topo->face_component[f] = component[t[0]];
  }
  // Closed components get a dense index; the rest are open.
  std::vector<uint32_t> closed_index(count, DisplayTopology::kOpen);
  for (uint32_t c = 0; c < count; ++c) {
    const Facts& x = facts[c];
    const double diag = x.box.diagonal();
    // A closed surface with (nearly) no volume, e.g. a sheet and its
    // reverse, has no inside that hides its back faces.
    if (x.balance != 0 || !(std::fabs(x.volume) > 1e-6 * diag * diag * diag)) continue;
    closed_index[c] = static_cast<uint32_t>(topo->closed.size());
    topo->closed.push_back({x.box, x.volume < 0 ? -1.0f : 1.0f});
  }
  for (uint32_t& c : topo->face_component) c = closed_index[c];
  return topo;
}

CulledDisplay cull_display(const std::shared_ptr<const Mesh>& mesh_shared,
                           const std::shared_ptr<const std::vector<FaceKind>>& face_kind,
                           const DisplayTopology& topology, const AsaCamera& camera,
                           float near_plane, const CullMargins& margins) {
  CulledDisplay out;
  out.mesh = mesh_shared;
  out.face_kind = face_kind;
  const Mesh& mesh = *mesh_shared;
  const uint32_t V = mesh.vertex_count(), F = mesh.face_count();
  if (F == 0 || topology.face_component.size() != F) {
    out.visible_faces = F;
    return out;
  }
  const Vec3f eye = camera.eye;
  const Vec3f axis = normalized(camera.target - camera.eye);
  const float r = margins.eye_share * length(camera.target - camera.eye);
  const float half =
      std::min(corner_half_angle(camera) + margins.angle_degrees * kDegrees, kMaxHalfAngle);
  const float sin_h = std::sin(half), cos_h = std::cos(half);
  const Vec3f apex = eye - axis * (r / sin_h);
  // Any basis across the axis: the square pyramid contains the whole cone.
  Vec3f across = std::fabs(axis.y) < 0.9f ? Vec3f{0, 1, 0} : Vec3f{1, 0, 0};
  const Vec3f right = normalized(cross(axis, across));
  const Vec3f up = cross(right, axis);
  const Vec3f planes[4] = {axis * sin_h - right * cos_h, axis * sin_h + right * cos_h,
                           axis * sin_h - up * cos_h, axis * sin_h + up * cos_h};

  // Which closed components hide their back faces from every valid eye.
  std::vector<uint8_t> hides(topology.closed.size(), 0);
  float near_limit = 1e30f;
  for (size_t c = 0; c < topology.closed.size(); ++c) {
    const float clear = (distance_to_box(eye, topology.closed[c].box) - r) * cos_h;
    if (clear > 0 && clear > near_plane) {
      hides[c] = 1;
      near_limit = std::min(near_limit, clear);
    }
  }

  std::vector<uint8_t> visible(F), mark(V, 0);
  uint32_t visible_count = 0;
  for (uint32_t f = 0; f < F; ++f) {
    const Triangle& t = mesh.triangles[f];
    const Vec3f a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
    bool seen = true;
    for (const Vec3f& n : planes) {
      if (dot(n, a - apex) < 0 && dot(n, b - apex) < 0 && dot(n, c - apex) < 0) {
        seen = false;
        ++out.frustum_culled;
        break;
      }
    }
    const uint32_t comp = topology.face_component[f];
    if (seen && comp != DisplayTopology::kOpen && hides[comp]) {
      const Vec3f normal = cross(b - a, c - a);
      const float side = topology.closed[comp].sign * dot(normal, eye - a);
      if (side < 0 && side * side > r * r * dot(normal, normal)) {
        seen = false;
        ++out.back_culled;
      }
    }
    visible[f] = seen;
    if (seen) {
      ++visible_count;
      mark[t[0]] = mark[t[1]] = mark[t[2]] = 1;
    }
  }
  out.visible_faces = visible_count;
  // The skirt: every face around a vertex of a visible face, so that vertex
  // gets the same shading normal as in the whole mesh.
  std::vector<uint32_t> kept;
  kept.reserve(visible_count + visible_count / 8);
  for (uint32_t f = 0; f < F; ++f) {
    const Triangle& t = mesh.triangles[f];
    if (visible[f] || mark[t[0]] || mark[t[1]] || mark[t[2]]) kept.push_back(f);
  }
  if (kept.size() == F) return out;

  out.region.everything = false;
  out.region.eye = eye;
  out.region.eye_radius = r;
  out.region.apex = apex;
  out.region.axis = axis;
  out.region.cone_half_angle = half;
  out.region.near_limit = near_limit;

  constexpr uint32_t kUnused = 0xFFFFFFFFu;
  std::vector<uint32_t> remap(V, kUnused);
  for (uint32_t f : kept)
    for (uint32_t v : mesh.triangles[f]) remap[v] = 0;
  auto culled = std::make_shared<Mesh>();
  Mesh& m = *culled;
  uint32_t next = 0;
  for (uint32_t v = 0; v < V; ++v)
    if (remap[v] == 0) remap[v] = next++;
  m.positions.resize(next);
  const bool normals = mesh.normals.size() == V, colors = mesh.colors.size() == V,
             texcoords = mesh.texcoords.size() == V;
  if (normals) m.normals.resize(next);
  if (colors) m.colors.resize(next);
  if (texcoords) m.texcoords.resize(next);
  for (uint32_t v = 0; v < V; ++v) {
    const uint32_t w = remap[v];
    if (w == kUnused) continue;
    m.positions[w] = mesh.positions[v];
    if (normals) m.normals[w] = mesh.normals[v];
    if (colors) m.colors[w] = mesh.colors[v];
    if (texcoords) m.texcoords[w] = mesh.texcoords[v];
  }
  m.triangles.reserve(kept.size());
  for (uint32_t f : kept) {
    const Triangle& t = mesh.triangles[f];
    m.triangles.push_back({remap[t[0]], remap[t[1]], remap[t[2]]});
  }
  auto corners = [&](const auto& from, auto& to) {
    if (from.empty()) return;
    to.values = from.values;
    to.corners.reserve(3 * kept.size());
    for (uint32_t f : kept)
      for (int k = 0; k < 3; ++k) to.corners.push_back(from.corners[3 * size_t(f) + k]);
  };
  corners(mesh.corner_normals, m.corner_normals);
  corners(mesh.corner_colors, m.corner_colors);
  corners(mesh.corner_texcoords, m.corner_texcoords);
  m.materials = mesh.materials;
  m.textures = mesh.textures;
  if (mesh.face_materials.size() == F) {
    m.face_materials.reserve(kept.size());
    for (uint32_t f : kept) m.face_materials.push_back(mesh.face_materials[f]);
  }
  for (const ExtraAttribute& extra : mesh.extra_attributes) {
    ExtraAttribute e = extra;
    const size_t per_face = extra.bytes.size() / std::max<size_t>(F, 1);
    e.bytes.clear();
    if (per_face * F == extra.bytes.size()) {
      e.bytes.reserve(per_face * kept.size());
      for (uint32_t f : kept)
        e.bytes.insert(e.bytes.end(), extra.bytes.begin() + per_face * f,
                       extra.bytes.begin() + per_face * (f + 1));
    }
    m.extra_attributes.push_back(std::move(e));
  }
  if (face_kind && face_kind->size() == F) {
    auto kinds = std::make_shared<std::vector<FaceKind>>();
    kinds->reserve(kept.size());
    for (uint32_t f : kept) kinds->push_back((*face_kind)[f]);
    out.face_kind = std::move(kinds);
  } else {
    out.face_kind = nullptr;
  }
  out.mesh = std::move(culled);
  return out;
}

bool cull_valid_for(const CullRegion& region, const AsaCamera& camera, float near_plane) {
  if (region.everything) return true;
  if (!(length(camera.eye - region.eye) <= region.eye_radius)) return false;
  if (!(near_plane < region.near_limit)) return false;
  const Vec3f axis = normalized(camera.target - camera.eye);
  const float between = std::acos(std::clamp(dot(axis, region.axis), -1.0f, 1.0f));
  return between + corner_half_angle(camera) <= region.cone_half_angle;
}

}  // namespace meshstream
