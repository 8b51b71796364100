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

namespace {

Status attribute_error(const std::string& what) {
  return make_error(ErrorCode::kInvalidMesh, what);
}

// A corner attribute is empty, or has one in-range value index per corner.
template <typename T>
Status check_corner_attribute(const CornerAttribute<T>& attribute, size_t corner_count,
                              size_t per_vertex_size, const char* kind) {
  if (attribute.corners.empty()) {
    if (!attribute.values.empty()) {
      return attribute_error(std::string("per-corner ") + kind + " have values but no corners");
    }
    return {};
  }
  if (per_vertex_size != 0) {
    return attribute_error(std::string(kind) + " are given both per vertex and per corner");
  }
  if (attribute.corners.size() != corner_count) {
    return attribute_error(std::string("per-corner ") + kind + ": " +
                           std::to_string(attribute.corners.size()) + " corners for " +
                           std::to_string(corner_count / 3) + " triangles");
  }
  for (size_t c = 0; c < corner_count; ++c) {
    if (attribute.corners[c] >= attribute.values.size()) {
      return attribute_error(std::string("per-corner ") + kind + ": corner " + std::to_string(c) +
                             " refers to value " + std::to_string(attribute.corners[c]) +
                             " but there are only " + std::to_string(attribute.values.size()));
    }
  }
  return {};
}

Status check_texture_index(int32_t index, size_t texture_count, size_t material) {
  if (index < -1 || (index >= 0 && static_cast<size_t>(index) >= texture_count)) {
    return attribute_error("material " + std::to_string(material) + " refers to texture " +
                           std::to_string(index) + " but there are only " +
                           std::to_string(texture_count));
  }
  return {};
}

}  // namespace

Status check_attribute_counts(const Mesh& mesh) {
  const size_t n = mesh.positions.size();
  auto attribute_ok = [n](size_t size) { return size == 0 || size == n; };
  if (!attribute_ok(mesh.normals.size()) || !attribute_ok(mesh.colors.size()) ||
      !attribute_ok(mesh.texcoords.size())) {
    return attribute_error("per-vertex attribute count does not match the " + std::to_string(n) +
                           " vertices");
  }
  const size_t corners = 3 * mesh.triangles.size();
  if (auto ok =
          check_corner_attribute(mesh.corner_normals, corners, mesh.normals.size(), "normals");
      !ok) {
    return ok;
  }
  if (auto ok = check_corner_attribute(mesh.corner_colors, corners, mesh.colors.size(), "colours");
      !ok) {
    return ok;
  }
  if (auto ok = check_corner_attribute(mesh.corner_texcoords, corners, mesh.texcoords.size(),
                                       "texture coordinates");
      !ok) {
    return ok;
  }
  for (const ExtraAttribute& extra : mesh.extra_attributes) {
    if (extra.components < 1 || extra.components > 4) {
      return attribute_error("attribute " + extra.name + " has " +
                             std::to_string(extra.components) + " components (1 to 4 allowed)");
    }
    if (extra.bytes.size() != corners * element_size(extra)) {
      return attribute_error("attribute " + extra.name + " has " +
                             std::to_string(extra.bytes.size()) + " bytes, not one element for " +
                             "each of the " + std::to_string(corners) + " corners");
    }
  }
  if (!mesh.face_materials.empty()) {
    if (mesh.face_materials.size() != mesh.triangles.size()) {
      return attribute_error("face materials: " + std::to_string(mesh.face_materials.size()) +
                             " entries for " + std::to_string(mesh.triangles.size()) +
                             " triangles");
    }
    for (size_t f = 0; f < mesh.face_materials.size(); ++f) {
      if (mesh.face_materials[f] >= mesh.materials.size()) {
        return attribute_error("triangle " + std::to_string(f) + " uses material " +
                               std::to_string(mesh.face_materials[f]) + " but there are only " +
                               std::to_string(mesh.materials.size()));
      }
    }
  }
  for (size_t m = 0; m < mesh.materials.size(); ++m) {
    const Material& material = mesh.materials[m];
    for (int32_t texture :
         {material.base_color_texture, material.normal_texture, material.metallic_roughness_texture,
          material.occlusion_texture, material.emissive_texture}) {
      if (auto ok = check_texture_index(texture, mesh.textures.size(), m); !ok) return ok;
    }
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
