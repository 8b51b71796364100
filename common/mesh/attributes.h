// What a mesh carries besides positions and per-vertex attributes: values
// that differ between the corners of one vertex (seams), materials, the
// images they use, and attributes we carry without modelling them. Plain
// data; Mesh (mesh.h) holds one of each.
//
// Why per corner: a glTF or OBJ file splits a vertex wherever its normal or
// texture coordinate differs across an edge (a UV island's border, a hard
// edge's normals). The codec and ASA need the welded surface, so import
// welds the positions and keeps, for each such attribute, the distinct
// values and which value every corner uses — Draco's layout (attribute
// values over the position connectivity, seams where two corners of one
// vertex disagree).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/mesh/vec.h"

namespace meshstream {

// An attribute with seams. `corners` has one entry per corner (3 per
// triangle, in triangle order: corner 3f+k is corner k of triangle f), each
// an index into `values`. Empty (both arrays) when the mesh has none.
template <typename T>
struct CornerAttribute {
  std::vector<T> values;
  std::vector<uint32_t> corners;
  bool empty() const { return corners.empty(); }
  const T& at_corner(size_t corner) const { return values[corners[corner]]; }
};

// An image as the file had it: the original PNG or JPEG bytes, never
// re-encoded, so a round trip gives the same file back.
struct Texture {
  std::string name;       // file name or glTF image name, for messages and export
  std::string mime_type;  // "image/png" or "image/jpeg"
  std::vector<uint8_t> bytes;
};

// The part of a material we show and write back: a base colour and its
// texture (glTF pbrMetallicRoughness baseColor*, OBJ/MTL Kd and map_Kd).
// Other maps (normal, occlusion, metallic-roughness, emissive, sheen, ...)
// travel as textures too when import keeps them; which ones are kept, and
// which are named in a warning, is import's decision (see CleanReport).
struct Material {
  std::string name;
  Vec4f base_color{1.0f, 1.0f, 1.0f, 1.0f};  // linear RGBA factor
  int32_t base_color_texture = -1;           // index into Mesh::textures, -1: none
  uint32_t base_color_texcoord_set = 0;      // which UV set the texture reads (0 only, today)
  int32_t normal_texture = -1;               // index into Mesh::textures, -1: none
  int32_t metallic_roughness_texture = -1;
  int32_t occlusion_texture = -1;
  int32_t emissive_texture = -1;
  float metallic = 1.0f, roughness = 1.0f;  // glTF defaults
  bool double_sided = false;
};

// An attribute the codec does not model (tangents, a second UV set, joints
// and weights, custom ones): carried byte for byte, one element per corner,
// so it survives welding and every vertex split without being understood.
struct ExtraAttribute {
  enum class ComponentType : uint8_t { kInt8, kUint8, kInt16, kUint16, kUint32, kFloat32 };
  std::string name;  // glTF semantic ("TANGENT", "TEXCOORD_1", "JOINTS_0") or PLY property
  ComponentType component_type = ComponentType::kFloat32;
  uint8_t components = 1;      // 1..4
  bool normalized = false;     // glTF's "normalized" flag for integer types
  std::vector<uint8_t> bytes;  // 3 * faces * element_size(), corner order as CornerAttribute
};

// Bytes of one component of `type`.
inline uint32_t component_size(ExtraAttribute::ComponentType type) {
  switch (type) {
    case ExtraAttribute::ComponentType::kInt8:
    case ExtraAttribute::ComponentType::kUint8:
      return 1;
    case ExtraAttribute::ComponentType::kInt16:
    case ExtraAttribute::ComponentType::kUint16:
      return 2;
    case ExtraAttribute::ComponentType::kUint32:
    case ExtraAttribute::ComponentType::kFloat32:
      return 4;
  }
  return 4;
}

inline uint32_t element_size(const ExtraAttribute& attribute) {
  return component_size(attribute.component_type) * attribute.components;
}

}  // namespace meshstream
