// Frustum and hidden back-face culling of a display mesh; see display_cull.h
// for why the picture cannot change.
#include "common/asa/display_cull.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "common/base/parallel_blocks.h"
#include "common/mesh/corner_data.h"
#include "common/mesh/union_find.h"

namespace meshstream {
namespace {

constexpr float kDegrees = static_cast<float>(std::numbers::pi) / 180.0f;
// The widened cone stays a cone (a half-angle near 90 degrees would put
// the apex at infinity).
constexpr float kMaxHalfAngle = 85.0f * kDegrees;

double det(Vec3f a, Vec3f b, Vec3f c) {
  return double(a.x) * (double(b.y) * c.z - double(b.z) * c.y) +
         double(a.y) * (double(b.z) * c.x - double(b.x) * c.z) +
         double(a.z) * (double(b.x) * c.y - double(b.y) * c.x);
}

void grow(BoundingBox& b, Vec3f p) {
  b.min = {std::min(b.min.x, p.x), std::min(b.min.y, p.y), std::min(b.min.z, p.z)};
  b.max = {std::max(b.max.x, p.x), std::max(b.max.y, p.y), std::max(b.max.z, p.z)};
}

constexpr BoundingBox kEmptyBox{{1e30f, 1e30f, 1e30f}, {-1e30f, -1e30f, -1e30f}};

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

std::shared_ptr<const SourceTopology> analyze_source_topology(const Mesh& mesh) {
  auto topo = std::make_shared<SourceTopology>();
  constexpr uint32_t kNone = SourceTopology::kNone;
  const uint32_t V = mesh.vertex_count(), F = mesh.face_count();
  UnionFind sets(V);
  for (const Triangle& t : mesh.triangles) {
    sets.unite(t[0], t[1]);
    sets.unite(t[0], t[2]);
  }
  // Components numbered by their smallest vertex.
  std::vector<uint32_t>& component = topo->vertex_component;
  component.assign(V, kNone);
  uint32_t count = 0;
  for (uint32_t v = 0; v < V; ++v) {
    const uint32_t root = sets.find(v);
    if (component[root] == kNone) component[root] = count++;
    component[v] = component[root];
  }
  std::vector<uint8_t> unusable(count, 0);
  std::vector<double> volume(count, 0);
  std::vector<BoundingBox> box(count, kEmptyBox);
  for (uint32_t v = 0; v < V; ++v) grow(box[component[v]], mesh.positions[v]);
  const BoundingBox all = bounding_box(mesh);
  const Vec3f o = (all.min + all.max) * 0.5f;
  // The directed edges out of each vertex (counting sort by tail).
  std::vector<uint32_t> first(V + 1, 0), head(3 * size_t(F));
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++first[t[k] + 1];
  for (uint32_t v = 0; v < V; ++v) first[v + 1] += first[v];
  {
    std::vector<uint32_t> at(first.begin(), first.end() - 1);
    for (const Triangle& t : mesh.triangles)
      for (int k = 0; k < 3; ++k) head[at[t[k]]++] = t[(k + 1) % 3];
  }
  auto uses = [&](uint32_t a, uint32_t b) {
    uint32_t n = 0;
    for (uint32_t i = first[a]; i < first[a + 1]; ++i) n += head[i] == b;
    return n;
  };
  for (uint32_t f = 0; f < F; ++f) {
    const Triangle& t = mesh.triangles[f];
    volume[component[t[0]]] +=
        det(mesh.positions[t[0]] - o, mesh.positions[t[1]] - o, mesh.positions[t[2]] - o);
  }
  // Boundary edges (used once, never the other way): the next boundary
  // vertex of each; anything else that is not used once each way makes the
  // component unusable.
  std::vector<uint32_t> next(V, kNone);
  for (uint32_t a = 0; a < V; ++a) {
    for (uint32_t i = first[a]; i < first[a + 1]; ++i) {
      const uint32_t b = head[i];
      const uint32_t forward = uses(a, b), backward = uses(b, a);
      if (forward == 1 && backward == 0) {
        if (next[a] != kNone) unusable[component[a]] = 1;  // two loops through a
        next[a] = b;
      } else if (forward != 1 || backward != 1) {
        unusable[component[a]] = 1;
      }
    }
  }
  // Each loop: a ball around it, and the volume of its cap (a fan from its
  // centroid, wound against the boundary edges so the capped surface closes).
  struct LoopHole {
    uint32_t component;
    SourceTopology::Hole hole;
  };
  std::vector<LoopHole> loops;
  std::vector<uint32_t> loop_vertices;
  for (uint32_t start = 0; start < V; ++start) {
    if (next[start] == kNone) continue;
    loop_vertices.clear();
    uint32_t v = start;
    bool closed = false;
    while (next[v] != kNone && loop_vertices.size() <= V) {
      loop_vertices.push_back(v);
      const uint32_t w = next[v];
      next[v] = kNone;  // visited
      v = w;
      if (v == start) {
        closed = true;
        break;
      }
    }
    const uint32_t c = component[start];
    if (!closed) {
      unusable[c] = 1;
      continue;
    }
    Vec3f centre{0, 0, 0};
    for (uint32_t u : loop_vertices) centre = centre + mesh.positions[u];
    centre = centre / float(loop_vertices.size());
    float radius = 0, longest = 0;
    for (size_t i = 0; i < loop_vertices.size(); ++i) {
      const Vec3f a = mesh.positions[loop_vertices[i]];
      const Vec3f b = mesh.positions[loop_vertices[(i + 1) % loop_vertices.size()]];
      radius = std::max(radius, length(a - centre));
      longest = std::max(longest, length(b - a));
      volume[c] += det(centre - o, b - o, a - o);
    }
    loops.push_back({c, {centre, radius + 2 * longest}});
  }
  std::stable_sort(loops.begin(), loops.end(),
                   [](const LoopHole& a, const LoopHole& b) { return a.component < b.component; });
  topo->components.resize(count);
  for (uint32_t c = 0; c < count; ++c) {
    const double diag = box[c].diagonal();
    SourceTopology::Component& k = topo->components[c];
    // A capped surface with (nearly) no volume, e.g. a sheet and its
    // reverse, has no inside that hides its back faces.
    k.usable = !unusable[c] && std::fabs(volume[c]) > 1e-6 * diag * diag * diag;
    k.sign = volume[c] < 0 ? -1.0f : 1.0f;
  }
  for (size_t i = 0; i < loops.size(); ++i) {
    SourceTopology::Component& k = topo->components[loops[i].component];
    if (k.holes == 0) k.first_hole = static_cast<uint32_t>(i);
    ++k.holes;
    topo->holes.push_back(loops[i].hole);
  }
  return topo;
}

std::shared_ptr<const DisplayTopology> analyze_display_topology(const Mesh& mesh,
                                                                const SourceTopology& source) {
  auto topo = std::make_shared<DisplayTopology>();
  constexpr uint32_t kNone = SourceTopology::kNone;
  const uint32_t V = mesh.vertex_count(), F = mesh.face_count();
  const uint32_t Vs = std::min<uint32_t>(V, uint32_t(source.vertex_component.size()));
  // Old vertices keep their component; a new one takes that of a face it
  // shares with a vertex that has one (one pass per ASA level).
  std::vector<uint32_t> component(V, kNone);
  std::copy(source.vertex_component.begin(), source.vertex_component.begin() + Vs,
            component.begin());
  std::vector<uint32_t>& face_component = topo->face_component;
  face_component.assign(F, kNone);
  for (int pass = 0; pass < 8; ++pass) {
    bool missing = false, progress = false;
    for (uint32_t f = 0; f < F; ++f) {
      if (face_component[f] != kNone) continue;
      const Triangle& t = mesh.triangles[f];
      uint32_t c = kNone;
      for (uint32_t v : t)
        if (component[v] != kNone) c = component[v];
      if (c == kNone) {
        missing = true;
        continue;
      }
      face_component[f] = c;
      progress = true;
      for (uint32_t v : t)
        if (component[v] == kNone) component[v] = c;
    }
    if (!missing || !progress) break;
  }
  // Dense indices for the usable components; their boxes over the display.
  std::vector<uint32_t> dense(source.components.size(), DisplayTopology::kOpen);
  for (size_t c = 0; c < source.components.size(); ++c) {
    const SourceTopology::Component& k = source.components[c];
    if (!k.usable) continue;
    dense[c] = static_cast<uint32_t>(topo->closed.size());
    DisplayTopology::Component d;
    d.box = kEmptyBox;
    d.sign = k.sign;
    d.first_hole = static_cast<uint32_t>(topo->holes.size());
    d.holes = k.holes;
    topo->holes.insert(topo->holes.end(), source.holes.begin() + k.first_hole,
                       source.holes.begin() + k.first_hole + k.holes);
    topo->closed.push_back(d);
  }
  for (uint32_t v = 0; v < V; ++v)
    if (component[v] != kNone && dense[component[v]] != DisplayTopology::kOpen)
      grow(topo->closed[dense[component[v]]].box, mesh.positions[v]);
  for (uint32_t f = 0; f < F; ++f) {
    const Triangle& t = mesh.triangles[f];
    const uint32_t c = face_component[f];
    // A face whose vertices disagree (not a display of this source) hides nothing.
    const bool agree =
        c != kNone && component[t[0]] == c && component[t[1]] == c && component[t[2]] == c;
    face_component[f] = agree ? dense[c] : DisplayTopology::kOpen;
  }
  return topo;
}

std::shared_ptr<const DisplayTopology> analyze_display_topology(const Mesh& mesh) {
  return analyze_display_topology(mesh, *analyze_source_topology(mesh));
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

  // Which closed components hide their back faces from every valid eye,
  // and the cone of lines from those eyes through each of their holes
  // (apex the eye, tan of its half-angle (r + radius) / (distance - radius
  // - r): a point seen through the hole from any eye within r lies inside).
  struct HoleCone {
    Vec3f axis;
    float sin = 0, cos = 1;
  };
  std::vector<HoleCone> cones(topology.holes.size());
  std::vector<uint8_t> hides(topology.closed.size(), 0);
  float near_limit = 1e30f;
  for (size_t c = 0; c < topology.closed.size(); ++c) {
    const DisplayTopology::Component& k = topology.closed[c];
    const float clear = (distance_to_box(eye, k.box) - r) * cos_h;
    if (!(clear > 0 && clear > near_plane)) continue;
    bool ok = true;
    for (uint32_t h = k.first_hole; h < k.first_hole + k.holes; ++h) {
      const SourceTopology::Hole& hole = topology.holes[h];
      const Vec3f to = hole.centre - eye;
      const float d = length(to), room = d - hole.radius - r;
      if (!(room > 0)) {
        ok = false;  // the eye may be in the hole
        break;
      }
      const float t = (r + hole.radius) / room;
      cones[h] = {to / d, t / std::sqrt(1 + t * t), 1 / std::sqrt(1 + t * t)};
    }
    if (!ok) continue;
    hides[c] = 1;
    near_limit = std::min(near_limit, clear);
  }
  // The hole cones drawn into a grid over the image plane at depth 1 (the
  // eye's frame, the widened cone's square): a face whose footprint there
  // touches a marked cell may be seen through a hole and stays. Each cone
  // and footprint is drawn conservatively: an angle a at angle phi from the
  // axis moves the image-plane point by at most a / cos^2(phi + a). (An
  // exact cone test per hole where a cell is marked trimmed 12 % more faces
  // of dragon_res2, at a cost that grew with the holes.)
  constexpr int kGrid = 1024;  // cells of about a tenth of a degree
  const float extent = std::tan(half);
  const float cell = 2 * extent / kGrid;
  std::vector<uint8_t> through;
  auto image_point = [&](Vec3f rel, float& x, float& y, float& z) {
    z = dot(rel, axis);
    x = dot(rel, right) / z;
    y = dot(rel, up) / z;
  };
  auto spread = [](float phi, float a) {
    const float c = std::cos(std::min(phi + a, kMaxHalfAngle));
    return a / (c * c);
  };
  for (size_t c = 0; c < topology.closed.size(); ++c) {
    if (!hides[c]) continue;
    const DisplayTopology::Component& k = topology.closed[c];
    for (uint32_t h = k.first_hole; h < k.first_hole + k.holes; ++h) {
      if (through.empty()) through.assign(size_t(kGrid) * kGrid, 0);
      const HoleCone& cone = cones[h];
      float x, y, z;
      image_point(cone.axis, x, y, z);
      const float phi = std::acos(std::clamp(z, -1.0f, 1.0f));
      const float a = std::asin(std::clamp(cone.sin, 0.0f, 1.0f));
      if (z <= 0 || phi + a >= kMaxHalfAngle) {
        std::fill(through.begin(), through.end(), 1);  // a cone beside the view: keep all
        continue;
      }
      const float reach = spread(phi, a) + cell;
      const int x0 = std::max(0, int((x - reach + extent) / cell));
      const int x1 = std::min(kGrid - 1, int((x + reach + extent) / cell));
      const int y0 = std::max(0, int((y - reach + extent) / cell));
      const int y1 = std::min(kGrid - 1, int((y + reach + extent) / cell));
      for (int j = y0; j <= y1; ++j)
        for (int i = x0; i <= x1; ++i) {
          const float cx = -extent + (i + 0.5f) * cell - x, cy = -extent + (j + 0.5f) * cell - y;
          if (cx * cx + cy * cy <= reach * reach) through[size_t(j) * kGrid + i] = 1;
        }
    }
  }
  auto through_a_hole = [&](const DisplayTopology::Component& k, Vec3f a, Vec3f b, Vec3f c) {
    if (k.holes == 0) return false;
    const Vec3f centre = (a + b + c) / 3.0f;
    const float ball = std::sqrt(std::max({dot(a - centre, a - centre), dot(b - centre, b - centre),
                                           dot(c - centre, c - centre)})) *
                       1.0001f;
    const Vec3f rel = centre - eye;
    const float dist = length(rel);
    if (!(dist > 2 * ball)) return true;
    float x, y, z;
    image_point(rel, x, y, z);
    if (!(z > ball)) return true;
    // spread() without trigonometry: a <= tan a, and 1 / cos^2 = 1 + tan^2
    // with tan(phi + a) from the image point's distance to the centre.
    const float tan_a = ball / std::sqrt(dist * dist - ball * ball);
    const float t = std::sqrt(x * x + y * y);
    const float below = 1 - t * tan_a;
    if (!(below > 0.05f)) return true;
    const float tan_sum = (t + tan_a) / below;
    const float reach = tan_a * (1 + tan_sum * tan_sum);
    const int x0 = int((x - reach + extent) / cell), x1 = int((x + reach + extent) / cell);
    const int y0 = int((y - reach + extent) / cell), y1 = int((y + reach + extent) / cell);
    if (x0 < 0 || y0 < 0 || x1 >= kGrid || y1 >= kGrid) return true;
    for (int j = y0; j <= y1; ++j)
      for (int i = x0; i <= x1; ++i)
        if (through[size_t(j) * kGrid + i]) return true;
    return false;
  };
  // Which faces show: on both cores, in blocks that each write their own
  // flags and counts (the result does not depend on the thread count).
  std::vector<uint8_t> visible(F), mark(V, 0);
  constexpr uint32_t kBlock = 1u << 16;
  const size_t blocks = (size_t(F) + kBlock - 1) / kBlock;
  std::vector<uint32_t> frustum_out(blocks, 0), back_out(blocks, 0);
  for_each_block(blocks, F >= 4 * kBlock ? 0 : 1, [&](size_t block) {
    const uint32_t begin = uint32_t(block * kBlock), end = std::min(F, begin + kBlock);
    for (uint32_t f = begin; f < end; ++f) {
      const Triangle& t = mesh.triangles[f];
      const Vec3f a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
      bool seen = true;
      for (const Vec3f& n : planes) {
        if (dot(n, a - apex) < 0 && dot(n, b - apex) < 0 && dot(n, c - apex) < 0) {
          seen = false;
          ++frustum_out[block];
          break;
        }
      }
      const uint32_t comp = topology.face_component[f];
      if (seen && comp != DisplayTopology::kOpen && hides[comp]) {
        const Vec3f normal = cross(b - a, c - a);
        const float side = topology.closed[comp].sign * dot(normal, eye - a);
        if (side < 0 && side * side > r * r * dot(normal, normal) &&
            !through_a_hole(topology.closed[comp], a, b, c)) {
          seen = false;
          ++back_out[block];
        }
      }
      visible[f] = seen;
    }
  });
  uint32_t visible_count = 0;
  for (size_t block = 0; block < blocks; ++block) {
    out.frustum_culled += frustum_out[block];
    out.back_culled += back_out[block];
  }
  for (uint32_t f = 0; f < F; ++f) {
    if (!visible[f]) continue;
    ++visible_count;
    const Triangle& t = mesh.triangles[f];
    mark[t[0]] = mark[t[1]] = mark[t[2]] = 1;
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
  m.materials = mesh.materials;
  m.textures = mesh.textures;
  copy_face_data(mesh, kept, m);
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
