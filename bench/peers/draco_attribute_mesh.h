// Draco's reader as the attribute benches' input, and Draco's encoder at
// the attribute table's quantization (issue 18): a draco::Mesh (its points
// split at seams) as our Mesh (welded by position, attributes per vertex
// where every corner of a vertex agrees, else per corner), Draco's bytes for
// a mesh, and the mesh with only the first normal, texture coordinate and
// colour attribute (what we encode from it). Header-only, for
// attribute_bench and attribute_rd_bench.
#pragma once

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>

#include <algorithm>
#include <array>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/mesh/mesh.h"

namespace meshstream::bench {

// Values of `att` at point p as floats (n components).
inline std::vector<float> value_at(const draco::PointAttribute* att, draco::PointIndex p) {
  std::vector<float> out(att->num_components());
  att->ConvertValue<float>(att->mapped_index(p), att->num_components(), out.data());
  return out;
}

// Draco's mesh as ours: positions welded, attributes per vertex or corner.
inline Mesh to_mesh(const draco::Mesh& dm, std::string& kinds) {
  Mesh m;
  const auto* pos = dm.GetNamedAttribute(draco::GeometryAttribute::POSITION);
  std::map<std::array<float, 3>, uint32_t> ids;
  std::vector<uint32_t> vertex_of(dm.num_points());
  for (uint32_t p = 0; p < dm.num_points(); ++p) {
    const auto v = value_at(pos, draco::PointIndex(p));
    const std::array<float, 3> key{v[0], v[1], v[2]};
    auto it = ids.find(key);
    if (it == ids.end()) {
      it = ids.emplace(key, m.vertex_count()).first;
      m.positions.push_back({v[0], v[1], v[2]});
    }
    vertex_of[p] = it->second;
  }
  std::vector<uint32_t> corner_point;
  for (uint32_t f = 0; f < dm.num_faces(); ++f) {
    const auto& face = dm.face(draco::FaceIndex(f));
    m.triangles.push_back(
        {vertex_of[face[0].value()], vertex_of[face[1].value()], vertex_of[face[2].value()]});
    for (int k = 0; k < 3; ++k) corner_point.push_back(face[k].value());
  }
  // One attribute: per vertex when every corner of each vertex agrees.
  auto take = [&](draco::GeometryAttribute::Type type, auto& per_vertex, auto& per_corner,
                  auto make) {
    const auto* att = dm.GetNamedAttribute(type);
    if (!att) return;
    const uint32_t nv = m.vertex_count();
    std::vector<std::vector<float>> first(nv);
    bool seams = false;
    for (size_t c = 0; c < corner_point.size(); ++c) {
      const auto value = value_at(att, draco::PointIndex(corner_point[c]));
      auto& f = first[m.triangles[c / 3][c % 3]];
      if (f.empty())
        f = value;
      else if (f != value)
        seams = true;
    }
    if (!seams) {
      for (uint32_t v = 0; v < nv; ++v) per_vertex.push_back(make(first[v]));
    } else {
      std::map<std::vector<float>, uint32_t> index;
      for (size_t c = 0; c < corner_point.size(); ++c) {
        const auto value = value_at(att, draco::PointIndex(corner_point[c]));
        auto it = index.find(value);
        if (it == index.end()) {
          it = index.emplace(value, uint32_t(per_corner.values.size())).first;
          per_corner.values.push_back(make(value));
        }
        per_corner.corners.push_back(it->second);
      }
    }
    kinds += std::string(kinds.empty() ? "" : ", ") +
             (type == draco::GeometryAttribute::NORMAL      ? "normals"
              : type == draco::GeometryAttribute::TEX_COORD ? "uv"
                                                            : "colors") +
             (seams ? " (seams)" : "");
  };
  take(draco::GeometryAttribute::NORMAL, m.normals, m.corner_normals,
       [](const std::vector<float>& v) {
         return Vec3f{v[0], v[1], v[2]};
       });
  take(draco::GeometryAttribute::TEX_COORD, m.texcoords, m.corner_texcoords,
       [](const std::vector<float>& v) {
         return Vec2f{v[0], v[1]};
       });
  take(draco::GeometryAttribute::COLOR, m.colors, m.corner_colors, [](const std::vector<float>& v) {
    return Vec4f{v[0], v.size() > 1 ? v[1] : 0, v.size() > 2 ? v[2] : 0,
                 v.size() > 3 ? v[3] : 1.0f};
  });
  return m;
}

// Draco's bytes for `mesh` at -qp 12 -qn 8 -qt 12 -qg 8, speed 3 (draco_encoder's
// default -cl 7); 0 when it fails. `out`: the bytes themselves.
inline size_t draco_bytes(const draco::Mesh& mesh, std::vector<uint8_t>* out = nullptr) {
  draco::Encoder enc;
  enc.SetAttributeQuantization(draco::GeometryAttribute::POSITION, 12);
  enc.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, 8);
  enc.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, 12);
  enc.SetAttributeQuantization(draco::GeometryAttribute::GENERIC, 8);
  enc.SetSpeedOptions(3, 3);  // draco_encoder's default -cl 7
  draco::EncoderBuffer buffer;
  if (!enc.EncodeMeshToBuffer(mesh, &buffer).ok()) return 0;
  if (out) out->assign(buffer.data(), buffer.data() + buffer.size());
  return buffer.size();
}

// Draco's mesh with the first normal, texture coordinate and colour
// attribute (what we encode from it), minus the types in `drop`.
inline std::unique_ptr<draco::Mesh> draco_only(
    const draco::Mesh& in, const std::vector<draco::GeometryAttribute::Type>& drop) {
  auto m = std::make_unique<draco::Mesh>();
  m->Copy(in);
  for (int i = m->num_attributes() - 1; i >= 0; --i) {
    const auto type = m->attribute(i)->attribute_type();
    if (type == draco::GeometryAttribute::POSITION) continue;
    const bool modelled = type == draco::GeometryAttribute::NORMAL ||
                          type == draco::GeometryAttribute::TEX_COORD ||
                          type == draco::GeometryAttribute::COLOR;
    const bool first = m->GetNamedAttributeId(type) == i;
    if (!modelled || !first || std::find(drop.begin(), drop.end(), type) != drop.end())
      m->DeleteAttribute(i);
  }
  return m;
}

}  // namespace meshstream::bench
