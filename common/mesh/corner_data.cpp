#include "common/mesh/corner_data.h"

#include <string_view>
#include <unordered_map>
#include <utility>

namespace meshstream {
namespace {

template <typename T>
void keep_corners(CornerAttribute<T>& attribute, const std::vector<uint8_t>& keep) {
  if (attribute.empty()) return;
  size_t out = 0;
  for (size_t f = 0; f < keep.size(); ++f) {
    if (!keep[f]) continue;
    for (size_t k = 0; k < 3; ++k) attribute.corners[3 * out + k] = attribute.corners[3 * f + k];
    ++out;
  }
  attribute.corners.resize(3 * out);
}

void keep_extra(ExtraAttribute& extra, const std::vector<uint8_t>& keep) {
  const size_t corner_bytes = element_size(extra);
  const size_t face_bytes = 3 * corner_bytes;
  if (extra.bytes.size() != keep.size() * face_bytes) return;  // check_attribute_counts says so
  size_t out = 0;
  for (size_t f = 0; f < keep.size(); ++f) {
    if (!keep[f]) continue;
    if (out != f) {
      std::memmove(extra.bytes.data() + out * face_bytes, extra.bytes.data() + f * face_bytes,
                   face_bytes);
    }
    ++out;
  }
  extra.bytes.resize(out * face_bytes);
}

template <typename T>
void copy_corners(const CornerAttribute<T>& from, const std::vector<uint32_t>& faces,
                  CornerAttribute<T>& to) {
  to = {};
  if (from.empty()) return;
  to.values = from.values;
  to.corners.reserve(3 * faces.size());
  for (uint32_t f : faces)
    for (size_t k = 0; k < 3; ++k) to.corners.push_back(from.corners[3 * size_t(f) + k]);
}

template <typename T>
void swap_corners(CornerAttribute<T>& attribute, uint32_t f) {
  if (!attribute.empty()) std::swap(attribute.corners[3 * f + 1], attribute.corners[3 * f + 2]);
}

}  // namespace

void keep_faces(Mesh& mesh, const std::vector<uint8_t>& keep) {
  keep_corners(mesh.corner_normals, keep);
  keep_corners(mesh.corner_colors, keep);
  keep_corners(mesh.corner_texcoords, keep);
  for (ExtraAttribute& extra : mesh.extra_attributes) keep_extra(extra, keep);
  size_t out = 0;
  const bool materials = mesh.face_materials.size() == mesh.triangles.size();
  for (size_t f = 0; f < keep.size(); ++f) {
    if (!keep[f]) continue;
    mesh.triangles[out] = mesh.triangles[f];
    if (materials) mesh.face_materials[out] = mesh.face_materials[f];
    ++out;
  }
  mesh.triangles.resize(out);
  if (materials) mesh.face_materials.resize(out);
}

void copy_face_data(const Mesh& from, const std::vector<uint32_t>& faces, Mesh& to) {
  copy_corners(from.corner_normals, faces, to.corner_normals);
  copy_corners(from.corner_colors, faces, to.corner_colors);
  copy_corners(from.corner_texcoords, faces, to.corner_texcoords);
  to.face_materials.clear();
  if (from.face_materials.size() == from.triangles.size()) {
    to.face_materials.reserve(faces.size());
    for (uint32_t f : faces) to.face_materials.push_back(from.face_materials[f]);
  }
  to.extra_attributes.clear();
  for (const ExtraAttribute& extra : from.extra_attributes) {
    ExtraAttribute e = extra;
    e.bytes.clear();
    const size_t face_bytes = 3 * element_size(extra);
    if (extra.bytes.size() == from.triangles.size() * face_bytes) {
      e.bytes.reserve(faces.size() * face_bytes);
      for (uint32_t f : faces)
        e.bytes.insert(e.bytes.end(), extra.bytes.begin() + face_bytes * f,
                       extra.bytes.begin() + face_bytes * (f + 1));
    }
    to.extra_attributes.push_back(std::move(e));
  }
}

void reverse_face(Mesh& mesh, uint32_t f) {
  std::swap(mesh.triangles[f][1], mesh.triangles[f][2]);
  swap_corners(mesh.corner_normals, f);
  swap_corners(mesh.corner_colors, f);
  swap_corners(mesh.corner_texcoords, f);
  for (ExtraAttribute& extra : mesh.extra_attributes) {
    const size_t size = element_size(extra);
    if (extra.bytes.size() < (3 * static_cast<size_t>(f) + 3) * size) continue;
    uint8_t* one = extra.bytes.data() + (3 * static_cast<size_t>(f) + 1) * size;
    std::swap_ranges(one, one + size, one + size);
  }
}

bool has_corner_data(const Mesh& mesh) {
  return !mesh.corner_normals.empty() || !mesh.corner_colors.empty() ||
         !mesh.corner_texcoords.empty() || !mesh.extra_attributes.empty() ||
         !mesh.face_materials.empty();
}

template <typename T>
void compact_corner_values(CornerAttribute<T>& attribute) {
  if (attribute.empty()) {
    attribute.values.clear();
    return;
  }
  constexpr uint32_t kUnset = 0xFFFFFFFFu;
  std::vector<uint32_t> new_index(attribute.values.size(), kUnset);
  std::unordered_map<std::string_view, uint32_t> by_bits;
  by_bits.reserve(attribute.values.size());
  std::vector<T> values;
  for (uint32_t& corner : attribute.corners) {
    uint32_t& mapped = new_index[corner];
    if (mapped == kUnset) {
      const std::string_view key(reinterpret_cast<const char*>(&attribute.values[corner]),
                                 sizeof(T));
      auto [it, added] = by_bits.try_emplace(key, static_cast<uint32_t>(values.size()));
      if (added) values.push_back(attribute.values[corner]);
      mapped = it->second;
    }
    corner = mapped;
  }
  attribute.values = std::move(values);
}

template void compact_corner_values(CornerAttribute<Vec2f>&);
template void compact_corner_values(CornerAttribute<Vec3f>&);
template void compact_corner_values(CornerAttribute<Vec4f>&);

namespace {

template <typename T>
void settle(const Mesh& mesh, CornerAttribute<T>& corner, std::vector<T>& per_vertex,
            const T& fill) {
  if (corner.empty()) return;
  std::vector<T> flat = to_per_vertex_if_seamless(mesh, corner, fill);
  if (!flat.empty() || mesh.vertex_count() == 0) {
    per_vertex = std::move(flat);
    corner = {};
  } else {
    compact_corner_values(corner);
  }
}

}  // namespace

void settle_attribute_forms(Mesh& mesh) {
  settle(mesh, mesh.corner_normals, mesh.normals, Vec3f{0, 0, 0});
  settle(mesh, mesh.corner_colors, mesh.colors, Vec4f{1, 1, 1, 1});
  settle(mesh, mesh.corner_texcoords, mesh.texcoords, Vec2f{0, 0});
}

}  // namespace meshstream

namespace meshstream {

SplitMesh split_seams(const Mesh& mesh) {
  SplitMesh out;
  Mesh& m = out.mesh;
  m.triangles = mesh.triangles;
  m.materials = mesh.materials;
  m.face_materials = mesh.face_materials;
  m.textures = mesh.textures;
  m.positions = mesh.positions;
  m.normals = mesh.normals;
  m.colors = mesh.colors;
  m.texcoords = mesh.texcoords;
  const bool cn = !mesh.corner_normals.empty(), cc = !mesh.corner_colors.empty(),
             ct = !mesh.corner_texcoords.empty();
  const uint32_t n = mesh.vertex_count();
  if (cn) m.normals.assign(n, Vec3f{0, 0, 0});
  if (cc) m.colors.assign(n, Vec4f{1, 1, 1, 1});
  if (ct) m.texcoords.assign(n, Vec2f{0, 0});
  out.vertex_extras.resize(mesh.extra_attributes.size());
  for (size_t e = 0; e < mesh.extra_attributes.size(); ++e)
    out.vertex_extras[e].assign(static_cast<size_t>(n) * element_size(mesh.extra_attributes[e]), 0);
  if (!cn && !cc && !ct && mesh.extra_attributes.empty()) return out;

  // The key of a corner: its per-corner values' bytes.
  std::string key;
  auto corner_key = [&](size_t c) {
    key.clear();
    auto add = [&key](const void* p, size_t size) {
      key.append(static_cast<const char*>(p), size);
    };
    if (cn) add(&mesh.corner_normals.at_corner(c), sizeof(Vec3f));
    if (cc) add(&mesh.corner_colors.at_corner(c), sizeof(Vec4f));
    if (ct) add(&mesh.corner_texcoords.at_corner(c), sizeof(Vec2f));
    for (const ExtraAttribute& e : mesh.extra_attributes) {
      const size_t size = element_size(e);
      add(e.bytes.data() + c * size, size);
    }
  };
  std::vector<std::string> first_key(n);
  std::vector<uint8_t> seen(n, 0);
  std::unordered_map<std::string, uint32_t> copies;  // vertex bytes + key -> copy
  auto assign = [&](uint32_t v, size_t c) {
    if (cn) m.normals[v] = mesh.corner_normals.at_corner(c);
    if (cc) m.colors[v] = mesh.corner_colors.at_corner(c);
    if (ct) m.texcoords[v] = mesh.corner_texcoords.at_corner(c);
    for (size_t e = 0; e < mesh.extra_attributes.size(); ++e) {
      const size_t size = element_size(mesh.extra_attributes[e]);
      std::memcpy(out.vertex_extras[e].data() + static_cast<size_t>(v) * size,
                  mesh.extra_attributes[e].bytes.data() + c * size, size);
    }
  };
  for (size_t c = 0; c < 3 * mesh.triangles.size(); ++c) {
    uint32_t& v = m.triangles[c / 3][c % 3];
    corner_key(c);
    if (!seen[v]) {
      seen[v] = 1;
      first_key[v] = key;
      assign(v, c);
      continue;
    }
    if (first_key[v] == key) continue;
    std::string full(reinterpret_cast<const char*>(&v), sizeof v);
    full += key;
    auto [it, added] = copies.try_emplace(full, m.vertex_count());
    if (added) {
      const uint32_t original = v;
      m.positions.push_back(mesh.positions[original]);
      if (!m.normals.empty()) m.normals.push_back(m.normals[original]);
      if (!m.colors.empty()) m.colors.push_back(m.colors[original]);
      if (!m.texcoords.empty()) m.texcoords.push_back(m.texcoords[original]);
      for (size_t e = 0; e < mesh.extra_attributes.size(); ++e)
        out.vertex_extras[e].resize(out.vertex_extras[e].size() +
                                    element_size(mesh.extra_attributes[e]));
      assign(it->second, c);
      ++out.split_copies;
    }
    v = it->second;
  }
  return out;
}

}  // namespace meshstream
