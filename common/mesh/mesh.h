// The triangle mesh every module exchanges: plain arrays, nothing hidden.
//
// Optional per-vertex attributes are either empty or have exactly one entry
// per vertex. An attribute with seams (values that differ between the corners
// of one vertex) is held per corner instead (attributes.h); a mesh has each
// kind (normals, colours, texture coordinates) in at most one of the two
// forms. Adjacency (see adjacency.h) is a separate structure built from a Mesh.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "common/base/result.h"
#include "common/mesh/attributes.h"
#include "common/mesh/vec.h"

namespace meshstream {

using Triangle = std::array<uint32_t, 3>;

struct Mesh {
  std::vector<Vec3f> positions;
  std::vector<Triangle> triangles;
  std::vector<Vec3f> normals;    // optional, per vertex
  std::vector<Vec4f> colors;     // optional, per vertex, RGBA in [0, 1]
  std::vector<Vec2f> texcoords;  // optional, per vertex; v up (OBJ's way; glTF's v is 1 - v)

  // With seams: used instead of the per-vertex array of the same kind.
  CornerAttribute<Vec3f> corner_normals;
  CornerAttribute<Vec4f> corner_colors;
  CornerAttribute<Vec2f> corner_texcoords;

  std::vector<Material> materials;
  std::vector<uint32_t> face_materials;          // optional, per triangle: index into materials
  std::vector<Texture> textures;                 // images the materials use
  std::vector<ExtraAttribute> extra_attributes;  // carried, not modelled (attributes.h)

  uint32_t vertex_count() const { return static_cast<uint32_t>(positions.size()); }
  uint32_t face_count() const { return static_cast<uint32_t>(triangles.size()); }
  bool empty() const { return triangles.empty(); }
};

struct BoundingBox {
  Vec3f min{}, max{};
  float diagonal() const { return length(max - min); }
};

// Bounding box of the positions; {0,0,0}-{0,0,0} for an empty mesh. O(V).
BoundingBox bounding_box(const Mesh& mesh);

// Every per-vertex attribute array is empty or has one value per vertex,
// every corner attribute has 3 entries per triangle (each a valid index into
// its values) and is not doubled by a per-vertex array of its kind, every
// extra attribute has one element per corner, face_materials is empty or one
// valid index per triangle, and material texture indices are valid;
// kInvalidMesh naming the first broken rule otherwise. O(corners).
Status check_attribute_counts(const Mesh& mesh);

// Checks the array-level rules: attribute sizes match, every index is in
// range, no triangle repeats a vertex, every coordinate is finite.
// The error names the first offending element. O(V + F).
Status validate_arrays(const Mesh& mesh);

// Area-weighted per-vertex normals (unit length; zero for isolated vertices). O(V + F).
std::vector<Vec3f> compute_vertex_normals(const Mesh& mesh);

// Unit normal of triangle f (zero vector for a degenerate triangle).
Vec3f face_normal(const Mesh& mesh, uint32_t f);

}  // namespace meshstream
