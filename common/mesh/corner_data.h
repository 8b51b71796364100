// Keeping per-corner and per-face data (attributes.h) in step with the
// faces: every step that drops, reorders or flips faces (clean.cpp,
// manifold_repair.cpp) goes through these, so seams, materials and extra
// attributes follow their faces. Also the conversions between per-vertex
// and per-corner form that import and export need.
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

#include "common/mesh/mesh.h"

namespace meshstream {

// Keeps the faces f with keep[f] != 0 (in order), with their corner
// attributes, extra attributes and face materials. keep.size() must be the
// face count. Values of corner attributes are kept as they are (see
// compact_corner_values). O(F).
void keep_faces(Mesh& mesh, const std::vector<uint8_t>& keep);

// Copies the per-corner and per-face data of `faces` of `from` (corner
// attributes, extra attributes, face materials), in that order, into `to`,
// replacing its own: `to` is a mesh made of those faces (its triangles are
// the caller's, as their vertices may be renumbered). Values of corner
// attributes are copied whole; an extra attribute of the wrong size comes
// out empty. O(faces).
void copy_face_data(const Mesh& from, const std::vector<uint32_t>& faces, Mesh& to);

// Reverses face f's orientation by swapping its corners 1 and 2, with
// everything stored per corner (so a flipped face keeps its seams). O(1).
void reverse_face(Mesh& mesh, uint32_t f);

// Whether the mesh holds any per-corner or per-face data that keep_faces
// and reverse_face must carry.
bool has_corner_data(const Mesh& mesh);

// Bitwise equality: -0 and +0 differ, as in welding; NaN equals itself.
template <typename T>
bool same_bits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

// Vertices whose corners use values that differ (bitwise): the vertices on
// a seam of `attribute`. 0 for an empty attribute. O(V + corners).
template <typename T>
uint32_t count_seam_vertices(const Mesh& mesh, const CornerAttribute<T>& attribute) {
  if (attribute.empty()) return 0;
  constexpr uint32_t kUnset = 0xFFFFFFFFu;
  std::vector<uint32_t> first(mesh.vertex_count(), kUnset);
  std::vector<uint8_t> seam(mesh.vertex_count(), 0);
  uint32_t count = 0;
  for (size_t c = 0; c < attribute.corners.size(); ++c) {
    const uint32_t v = mesh.triangles[c / 3][c % 3];
    const uint32_t value = attribute.corners[c];
    if (first[v] == kUnset) {
      first[v] = value;
    } else if (!seam[v] && first[v] != value &&
               !same_bits(attribute.values[first[v]], attribute.values[value])) {
      seam[v] = 1;
      ++count;
    }
  }
  return count;
}

// The per-vertex array as a corner attribute: values are the per-vertex
// array itself, each corner uses its vertex's value.
template <typename T>
CornerAttribute<T> to_corner_attribute(const Mesh& mesh, const std::vector<T>& per_vertex) {
  CornerAttribute<T> attribute;
  attribute.values = per_vertex;
  attribute.corners.reserve(3 * mesh.triangles.size());
  for (const Triangle& t : mesh.triangles)
    attribute.corners.insert(attribute.corners.end(), t.begin(), t.end());
  return attribute;
}

// Per-vertex values when no vertex is on a seam (vertices no face uses get
// `fill`); empty when there is a seam. O(V + corners).
template <typename T>
std::vector<T> to_per_vertex_if_seamless(const Mesh& mesh, const CornerAttribute<T>& attribute,
                                         const T& fill) {
  std::vector<T> out(mesh.vertex_count(), fill);
  std::vector<uint8_t> set(mesh.vertex_count(), 0);
  for (size_t c = 0; c < attribute.corners.size(); ++c) {
    const uint32_t v = mesh.triangles[c / 3][c % 3];
    const T& value = attribute.values[attribute.corners[c]];
    if (!set[v]) {
      out[v] = value;
      set[v] = 1;
    } else if (!same_bits(out[v], value)) {
      return {};
    }
  }
  return out;
}

// Merges bitwise-equal values and drops values no corner uses, keeping the
// first use order; corners are renumbered. O(values + corners) expected.
template <typename T>
void compact_corner_values(CornerAttribute<T>& attribute);

// Moves each kind (normals, colours, texture coordinates) to the form it
// needs: a corner attribute without seams becomes per vertex, a per-vertex
// one stays. Then compacts what stays per corner.
void settle_attribute_forms(Mesh& mesh);

extern template void compact_corner_values(CornerAttribute<Vec2f>&);
extern template void compact_corner_values(CornerAttribute<Vec3f>&);
extern template void compact_corner_values(CornerAttribute<Vec4f>&);

}  // namespace meshstream

namespace meshstream {

// The mesh with every attribute per vertex, for formats that have no
// corners (PLY, OFF, glTF): a vertex whose corners use different values is
// split into one copy per distinct combination (position, normal, texture
// coordinate, colour, extra attributes' bytes). Original vertices keep their
// index (the first combination met); copies are appended. Extra attributes
// become per-vertex bytes in `vertex_extras` (one element per vertex, same
// order as mesh.extra_attributes). `split_copies` counts the copies made.
struct SplitMesh {
  Mesh mesh;  // per-vertex attributes only; extra_attributes left empty
  std::vector<std::vector<uint8_t>> vertex_extras;
  uint32_t split_copies = 0;
};
SplitMesh split_seams(const Mesh& mesh);

}  // namespace meshstream
