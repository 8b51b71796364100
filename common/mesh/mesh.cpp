#include "common/mesh/mesh.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace meshstream {

BoundingBox bounding_box(const Mesh& mesh) {
  if (mesh.positions.empty()) return {};
  BoundingBox box{mesh.positions[0], mesh.positions[0]};
  for (const Vec3f& p : mesh.positions) {
    box.min = {std::min(box.min.x, p.x), std::min(box.min.y, p.y), std::min(box.min.z, p.z)};
    box.max = {std::max(box.max.x, p.x), std::max(box.max.y, p.y), std::max(box.max.z, p.z)};
  }
  return box;
}

Status check_attribute_counts(const Mesh& mesh) {
  const size_t n = mesh.positions.size();
  auto attribute_ok = [n](size_t size) { return size == 0 || size == n; };
  if (!attribute_ok(mesh.normals.size()) || !attribute_ok(mesh.colors.size()) ||
      !attribute_ok(mesh.texcoords.size())) {
    return make_error(ErrorCode::kInvalidMesh, "per-vertex attribute count does not match the " +
                                                   std::to_string(n) + " vertices");
  }
  return {};
}

Status validate_arrays(const Mesh& mesh) {
  if (auto ok = check_attribute_counts(mesh); !ok) return ok;
  const size_t n = mesh.positions.size();
  for (size_t v = 0; v < n; ++v) {
    const Vec3f& p = mesh.positions[v];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      return make_error(ErrorCode::kInvalidMesh, "vertex " + std::to_string(v) +
                                                     " has a non-finite coordinate (NaN or Inf)");
    }
  }
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const Triangle& t = mesh.triangles[f];
    for (uint32_t i : t) {
      if (i >= n) {
        return make_error(ErrorCode::kInvalidMesh, "triangle " + std::to_string(f) +
                                                       " refers to vertex " + std::to_string(i) +
                                                       " but there are only " + std::to_string(n));
      }
    }
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) {
      return make_error(ErrorCode::kInvalidMesh,
                        "triangle " + std::to_string(f) + " repeats a vertex (degenerate)");
    }
  }
  return {};
}

Vec3f face_normal(const Mesh& mesh, uint32_t f) {
  const Triangle& t = mesh.triangles[f];
  Vec3d a = to_double(mesh.positions[t[0]]);
  Vec3d b = to_double(mesh.positions[t[1]]);
  Vec3d c = to_double(mesh.positions[t[2]]);
  return to_float(normalized(cross(b - a, c - a)));
}

std::vector<Vec3f> compute_vertex_normals(const Mesh& mesh) {
  std::vector<Vec3d> sum(mesh.positions.size());
  for (const Triangle& t : mesh.triangles) {
    Vec3d a = to_double(mesh.positions[t[0]]);
    Vec3d b = to_double(mesh.positions[t[1]]);
    Vec3d c = to_double(mesh.positions[t[2]]);
    Vec3d n = cross(b - a, c - a);  // length = 2 * area: area weighting for free
    for (uint32_t v : t) sum[v] += n;
  }
  std::vector<Vec3f> normals(sum.size());
  for (size_t v = 0; v < sum.size(); ++v) normals[v] = to_float(normalized(sum[v]));
  return normals;
}

}  // namespace meshstream
