// clean_mesh: from what a file holds to what the codec and ASA need — a
// welded, manifold, consistently oriented triangle mesh — counting every
// change in the CleanReport (repairs are visible, never silent).
//
// Order matters and follows ../shared/meshes/MANIFEST.md: weld bit-identical
// positions, then drop faces that repeat a vertex, then duplicate faces, then
// unreferenced vertices; only then look at the topology.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <sstream>

#include "common/mesh/adjacency.h"
#include "common/mesh/corner_data.h"
#include "common/mesh/edge_groups.h"
#include "common/mesh/import.h"
#include "common/mesh/manifold_repair.h"
#include "common/mesh/same_faces.h"
#include "common/mesh/topology.h"

namespace meshstream {
namespace {

std::array<uint32_t, 3> bits(const Vec3f& p) {
  std::array<uint32_t, 3> b;
  std::memcpy(b.data(), &p, sizeof(b));
  return b;
}

std::string describe_non_finite(const Vec3f& p) {
  auto one = [](float x) -> std::string {
    if (std::isnan(x)) return "NaN";
    if (std::isinf(x)) return x > 0 ? "Inf" : "-Inf";
    std::ostringstream s;
    s << x;
    return s.str();
  };
  return std::string("(") + one(p.x) + ", " + one(p.y) + ", " + one(p.z) + ")";
}

// Applies old->new vertex renumbering (kNone = removed; the first old vertex
// mapped to a new index provides its data) to positions and attributes.
template <class T>
void remap_array(std::vector<T>& values, const std::vector<uint32_t>& new_index,
                 uint32_t new_count) {
  if (values.empty()) return;
  std::vector<T> out(new_count);
  std::vector<uint8_t> written(new_count, 0);
  for (size_t v = 0; v < values.size(); ++v) {
    const uint32_t n = new_index[v];
    if (n == kNone || written[n]) continue;
    out[n] = values[v];
    written[n] = 1;
  }
  values.swap(out);
}

void renumber(Mesh& mesh, const std::vector<uint32_t>& new_index, uint32_t new_count) {
  remap_array(mesh.positions, new_index, new_count);
  remap_array(mesh.normals, new_index, new_count);
  remap_array(mesh.colors, new_index, new_count);
  remap_array(mesh.texcoords, new_index, new_count);
  for (Triangle& t : mesh.triangles) {
    for (uint32_t& v : t) v = new_index[v];
  }
}

// True when every group of merged vertices has bit-identical values:
// vertex v went to new_index[v], whose first vertex was first_of[new_index[v]].
template <class T>
bool consistent_after_merge(const std::vector<T>& values, const std::vector<uint32_t>& new_index,
                            const std::vector<uint32_t>& first_of) {
  if (values.empty()) return true;
  for (size_t v = 0; v < values.size(); ++v) {
    if (std::memcmp(&values[v], &values[first_of[new_index[v]]], sizeof(T)) != 0) return false;
  }
  return true;
}

uint64_t position_hash(const std::array<uint32_t, 3>& key) {
  uint64_t h = (key[0] * 0x9E3779B97F4A7C15ull) ^ (key[1] * 0xC2B2AE3D27D4EB4Full) ^
               (key[2] * 0x165667B19E3779F9ull);
  return h ^ (h >> 29);
}

// Merges vertices whose positions are bit-identical (so -0 and +0 stay
// apart, as the manifest counts them); each keeps the lowest index of its
// group, and the groups keep the order of their first vertices. An
// open-addressing table of the 96-bit keys, sized to the distinct positions
// expected (from the first vertices) and grown by doubling: an STL file's
// corners are about 6 copies of each position, so a table over every corner
// would be 6x too big (134 MB for 3.2M triangles). O(V); besides the result,
// 4 bytes a file vertex and 8-16 a distinct position.
uint32_t weld(Mesh& mesh) {
  const uint32_t n = mesh.vertex_count();
  size_t table_size = 1024;
  std::vector<uint32_t> table(table_size, kNone);  // first vertex of each position
  std::vector<uint32_t> new_index(n);
  std::vector<uint32_t> first_of;  // new index -> its first (lowest) file vertex
  // Puts v in the table: true when its position is new (the caller numbers
  // it), else v gets the number of the first vertex with that position.
  auto insert = [&table, &new_index, &mesh](uint32_t v) {
    const std::array<uint32_t, 3> key = bits(mesh.positions[v]);
    const size_t mask = table.size() - 1;
    uint32_t* slots = table.data();
    for (size_t slot = position_hash(key) & mask;; slot = (slot + 1) & mask) {
      const uint32_t other = slots[slot];
      if (other == kNone) {
        slots[slot] = v;
        return true;
      }
      if (bits(mesh.positions[other]) == key) {
        new_index[v] = new_index[other];
        return false;
      }
    }
  };
  auto grow = [&](size_t size) {
    table_size = size;
    table.assign(table_size, kNone);
    for (const uint32_t w : first_of) insert(w);
  };
  // After the first vertices, the table is sized once for the share of
  // distinct positions they had (a PLY file: all, an STL file: about 1/6),
  // so it rarely has to grow again; growing keeps it right either way.
  constexpr uint32_t kSample = 1 << 16;
  uint32_t count = 0;
  for (uint32_t v = 0; v < n;) {
    if (v == kSample) {
      const uint64_t expected = static_cast<uint64_t>(count) * n / kSample;
      size_t size = table_size;
      while (size < 2 * expected) size *= 2;
      if (size > table_size) grow(size);
      first_of.reserve(expected + expected / 8 + 16);
    }
    if (2 * (count + 1) > table_size) grow(2 * table_size);  // at most half full
    // Vertices that cannot fill the table past half, up to the sample's end.
    uint32_t end = static_cast<uint32_t>(std::min<uint64_t>(n, v + (table_size / 2 - count)));
    if (v < kSample) end = std::min(end, kSample);
    for (; v < end; ++v) {
      if (insert(v)) {
        new_index[v] = count++;
        first_of.push_back(v);
      }
    }
  }
  table = {};
  const uint32_t merged = n - count;
  if (merged == 0) return 0;

  // Values that differ between welded vertices are seams: kept per corner
  // (the corners still index the file's vertices, which are the values).
  auto check = [&](auto& values, auto& corner) {
    if (!consistent_after_merge(values, new_index, first_of)) {
      corner = to_corner_attribute(mesh, values);
      values.clear();
    }
  };
  check(mesh.normals, mesh.corner_normals);
  check(mesh.colors, mesh.corner_colors);
  check(mesh.texcoords, mesh.corner_texcoords);
  first_of = {};
  renumber(mesh, new_index, count);
  return merged;
}

bool repeats_a_vertex(const Triangle& t) { return t[0] == t[1] || t[1] == t[2] || t[2] == t[0]; }

uint32_t count_degenerate(const Mesh& mesh) {
  return static_cast<uint32_t>(
      std::count_if(mesh.triangles.begin(), mesh.triangles.end(), repeats_a_vertex));
}

uint32_t drop_degenerate(Mesh& mesh) {
  const size_t before = mesh.triangles.size();
  if (!has_corner_data(mesh)) {
    std::erase_if(mesh.triangles, repeats_a_vertex);
  } else {
    std::vector<uint8_t> keep(before);
    for (size_t f = 0; f < before; ++f) keep[f] = !repeats_a_vertex(mesh.triangles[f]);
    keep_faces(mesh, keep);
  }
  return static_cast<uint32_t>(before - mesh.triangles.size());
}

// Drops every face whose vertex set equals an earlier face's (either
// orientation); the first one stays and is flagged in `had_twin` (aligned
// with the remaining faces). Linear (same_faces.h).
uint32_t drop_duplicates(Mesh& mesh, std::vector<uint8_t>& had_twin) {
  const uint32_t f_count = mesh.face_count();
  std::vector<uint32_t> first = first_face_with_same_vertices(mesh);
  uint32_t dups = 0;
  for (uint32_t f = 0; f < f_count; ++f) {
    if (first[f] != f) ++dups;
  }
  had_twin.clear();
  if (dups == 0) return 0;
  std::vector<uint8_t> state(f_count, 0);  // 2: duplicate, 1: kept and had a twin
  for (uint32_t f = 0; f < f_count; ++f) {
    if (first[f] == f) continue;
    state[f] = 2;
    state[first[f]] = 1;
  }
  first = {};
  std::vector<uint8_t> keep(f_count);
  had_twin.reserve(f_count - dups);
  for (uint32_t f = 0; f < f_count; ++f) {
    keep[f] = state[f] != 2;
    if (keep[f]) had_twin.push_back(state[f]);
  }
  keep_faces(mesh, keep);
  return dups;
}

// After repair: a face that had a duplicate (nearly always its reverse: a
// double-sided triangle, as in the VRIP dragons) and now shares no edge with
// any other face was a flap hanging off the surface at non-manifold edges.
// It adds nothing to the surface and would be a component of its own for
// the codec: drop it. Returns the number of faces dropped.
// `groups`: the repaired mesh's edge groups (make_manifold hands them back).
uint32_t drop_isolated_twins(Mesh& mesh, const std::vector<uint8_t>& had_twin,
                             const EdgeGroups& groups) {
  if (had_twin.size() != mesh.triangles.size()) return 0;
  std::vector<uint8_t> shared_edges(mesh.face_count(), 0);
  for (uint32_t e = 0; e < groups.edge_count(); ++e) {
    if (groups.use_count(e) < 2) continue;
    for (uint32_t k = groups.begin[e]; k < groups.begin[e + 1]; ++k)
      shared_edges[groups.uses[k].face] = 1;
  }
  const uint32_t before = mesh.face_count();
  std::vector<uint8_t> keep(before);
  for (uint32_t f = 0; f < before; ++f) keep[f] = !had_twin[f] || shared_edges[f];
  keep_faces(mesh, keep);
  return before - mesh.face_count();
}

}  // namespace

uint32_t drop_unreferenced(Mesh& mesh) {
  const uint32_t n = mesh.vertex_count();
  std::vector<uint8_t> used(n, 0);
  for (const Triangle& t : mesh.triangles) {
    for (uint32_t v : t) used[v] = 1;
  }
  std::vector<uint32_t> new_index(n, kNone);
  uint32_t count = 0;
  for (uint32_t v = 0; v < n; ++v) {
    if (used[v]) new_index[v] = count++;
  }
  if (count == n) return 0;
  renumber(mesh, new_index, count);
  return n - count;
}

bool CleanReport::changed() const {
  return welded_vertices || degenerate_faces || duplicate_faces || unreferenced_vertices ||
         split_vertices || detached_faces || flipped_faces || double_sided_flaps || !notes.empty();
}

namespace {

Result<CleanReport> clean_faces(Mesh& mesh, const ImportOptions& options) {
  CleanReport report;
  report.vertices_in_file = mesh.vertex_count();
  report.faces_in_file = mesh.face_count();
  if (auto ok = check_attribute_counts(mesh); !ok) return tl::unexpected(ok.error());
  const size_t n = mesh.positions.size();
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    for (uint32_t v : mesh.triangles[f]) {
      if (v >= n) {
        return make_error(ErrorCode::kInvalidMesh,
                          "face " + std::to_string(f) + " refers to vertex " + std::to_string(v) +
                              " but there are only " + std::to_string(n) + " vertices");
      }
    }
  }
  for (size_t v = 0; v < n; ++v) {
    const Vec3f& p = mesh.positions[v];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      return make_error(ErrorCode::kInvalidMesh,
                        "vertex " + std::to_string(v) +
                            " has a non-finite coordinate (NaN/Inf): " + describe_non_finite(p));
    }
  }

  if (options.weld) report.welded_vertices = weld(mesh);
  if (options.keep_degenerate_faces && options.keep_nonmanifold) {
    report.degenerate_faces = count_degenerate(mesh);
  } else {
    report.degenerate_faces = drop_degenerate(mesh);
  }
  std::vector<uint8_t> had_twin;
  if (options.drop_duplicate_faces) report.duplicate_faces = drop_duplicates(mesh, had_twin);
  report.unreferenced_vertices = drop_unreferenced(mesh);
  if (mesh.triangles.empty()) {
    if (report.faces_in_file == 0) {
      return make_error(ErrorCode::kInvalidMesh, "no usable triangle: the mesh has no faces");
    }
    return make_error(ErrorCode::kInvalidMesh,
                      "no usable triangle: all " + std::to_string(report.faces_in_file) +
                          " faces are degenerate (a repeated vertex" +
                          (options.weld ? ", after welding equal positions)" : ")"));
  }

  EdgeGroups groups = build_edge_groups(mesh);
  UnionFind fans = two_face_fans(mesh, groups);
  const ManifoldCounts found = count_nonmanifold(mesh, groups, fans);
  report.nonmanifold_edges = found.nonmanifold_edges;
  report.nonmanifold_vertices = found.nonmanifold_vertices;
  if (options.keep_nonmanifold) return report;
  // Already what the corner table needs (no edge with more than two faces,
  // so "fans" mean the same to both): nothing to refuse or repair.
  if (found.manifold() && found.orientation_conflicts == 0) return report;
  if (!options.repair_nonmanifold) {
    groups = {};
    fans = UnionFind(0);
    if (auto status = check_manifold(mesh); !status) return tl::unexpected(status.error());
    return report;
  }
  const uint32_t vertices_before_repair = mesh.vertex_count();
  EdgeGroups repaired_groups;
  auto repaired = make_manifold(mesh, std::move(groups), std::move(fans), &repaired_groups);
  if (!repaired) return tl::unexpected(repaired.error());
  report.split_vertices = repaired->split_vertices;
  report.detached_faces = repaired->detached_faces;
  report.flipped_faces = repaired->flipped_faces;
  if (!options.drop_double_sided_flaps) repaired_groups = {};
  if (options.drop_double_sided_flaps) {
    report.double_sided_flaps = drop_isolated_twins(mesh, had_twin, repaired_groups);
    repaired_groups = {};
    if (report.double_sided_flaps > 0) {
      // Vertices only the flaps used: repair copies (appended after the
      // original vertices) were never really added; originals are unreferenced.
      std::vector<uint8_t> used(mesh.vertex_count(), 0);
      for (const Triangle& t : mesh.triangles) {
        for (uint32_t v : t) used[v] = 1;
      }
      for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
        if (used[v]) continue;
        if (v >= vertices_before_repair) {
          --report.split_vertices;
        } else {
          ++report.unreferenced_vertices;
        }
      }
      drop_unreferenced(mesh);
    }
    if (mesh.triangles.empty()) {
      return make_error(ErrorCode::kInvalidMesh,
                        "no usable triangle: every face is a double-sided flap");
    }
  }
  return report;
}

}  // namespace

Result<CleanReport> clean_mesh(Mesh& mesh, const ImportOptions& options) {
  auto report = clean_faces(mesh, options);
  if (!report) return report;
  // Welding and repair decide where the seams are: an attribute left
  // without one is per vertex, the rest per corner with its values merged.
  settle_attribute_forms(mesh);
  return report;
}

}  // namespace meshstream
