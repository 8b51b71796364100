// Exact comparisons of meshes with attributes (the codec tests and
// bench/attribute_bench): what an exact decoder must give back, and a
// mesh's faces as their corners' data, independent of vertex and face order.
#pragma once

#include <algorithm>
#include <array>
#include <vector>

#include "common/codec/attribute_quantize.h"
#include "common/codec/encoder.h"
#include "common/mesh/mesh.h"

namespace meshstream::testing {

// What the decoder must give back: positions on the grid, every attribute
// through its quantization.
inline Mesh expected_mesh(const Mesh& in, const EncodeOptions& o) {
  Mesh e = *quantized_reference(in, o.quant_bits);
  auto n = [&](Vec3f v) {
    return dequantize_normal(quantize_normal(v, o.quant_normal), o.quant_normal);
  };
  for (const Vec3f& v : in.normals) e.normals.push_back(n(v));
  e.corner_normals.corners = in.corner_normals.corners;
  for (const Vec3f& v : in.corner_normals.values) e.corner_normals.values.push_back(n(v));
  auto uv_grid = [&](const std::vector<Vec2f>& values) {
    return make_texcoord_grid(values.data(), values.size(), o.quant_uv);
  };
  const TexcoordGrid g1 = uv_grid(in.texcoords), g2 = uv_grid(in.corner_texcoords.values);
  for (const Vec2f& v : in.texcoords)
    e.texcoords.push_back(dequantize_texcoord(g1, quantize_texcoord(g1, v)));
  e.corner_texcoords.corners = in.corner_texcoords.corners;
  for (const Vec2f& v : in.corner_texcoords.values)
    e.corner_texcoords.values.push_back(dequantize_texcoord(g2, quantize_texcoord(g2, v)));
  auto c = [&](float x) {
    return dequantize_color_channel(quantize_color_channel(x, o.quant_color), o.quant_color);
  };
  for (const Vec4f& v : in.colors) e.colors.push_back({c(v.x), c(v.y), c(v.z), c(v.w)});
  e.face_materials = in.face_materials;
  e.materials = in.materials;
  e.extra_attributes = in.extra_attributes;
  return e;
}

// Every face as its corners' data (position, then every attribute, the
// extra attributes' bytes), rotated to start at its least corner; sorted.
// Two meshes are the same up to vertex and face order iff these are equal.
using Corner = std::vector<float>;
inline std::vector<std::array<Corner, 3>> faces_of(const Mesh& m) {
  std::vector<std::array<Corner, 3>> out;
  for (uint32_t f = 0; f < m.face_count(); ++f) {
    std::array<Corner, 3> face;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = m.triangles[f][k];
      const size_t c = 3 * size_t(f) + k;
      Corner& x = face[k];
      x = {m.positions[v].x, m.positions[v].y, m.positions[v].z};
      if (!m.normals.empty()) x.insert(x.end(), {m.normals[v].x, m.normals[v].y, m.normals[v].z});
      if (!m.corner_normals.empty()) {
        const Vec3f n = m.corner_normals.at_corner(c);
        x.insert(x.end(), {n.x, n.y, n.z});
      }
      if (!m.texcoords.empty()) x.insert(x.end(), {m.texcoords[v].x, m.texcoords[v].y});
      if (!m.corner_texcoords.empty()) {
        const Vec2f t = m.corner_texcoords.at_corner(c);
        x.insert(x.end(), {t.x, t.y});
      }
      if (!m.colors.empty())
        x.insert(x.end(), {m.colors[v].x, m.colors[v].y, m.colors[v].z, m.colors[v].w});
      if (!m.face_materials.empty()) x.push_back(float(m.face_materials[f]));
      for (const ExtraAttribute& e : m.extra_attributes) {
        const uint32_t es = element_size(e);
        for (uint32_t b = 0; b < es; ++b) x.push_back(e.bytes[c * es + b]);
      }
    }
    const int first = int(std::min_element(face.begin(), face.end()) - face.begin());
    std::rotate(face.begin(), face.begin() + first, face.end());
    out.push_back(face);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace meshstream::testing
