// Shading normals that keep creases sharp. One normal per vertex, averaged
// over all of its faces, rounds every sharp edge of a CAD part: a cube drawn
// that way looks like a soap bar. Here the faces around each vertex are
// grouped into smoothing groups: two faces that share an edge through the
// vertex belong to one group when their normals differ by at most the crease
// angle. Each group gets its own copy of the vertex with the area-weighted
// normal of the group's faces, so a corner whose faces meet at a sharper
// angle is drawn with one normal per side (the usual "auto smooth" of
// modelling tools). Plain arrays in, plain arrays out; no GL here.
#pragma once

#include <cstdint>
#include <vector>

#include "common/mesh/mesh.h"

namespace meshstream::client {

// The renderer's angle when the user gives none (`--crease` off): flat
// enough that a coarse mesh of a smooth surface stays smooth (the bunny's
// 590-face base mesh has few edges bending more than 60 degrees), sharp
// enough that every 90-degree edge of a machined part stays sharp.
inline constexpr float kDefaultShadingCreaseDegrees = 60.0f;

struct ShadingMesh {
  // The input's vertices first (same indices), then one copy per extra
  // smoothing group, in vertex order.
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;  // one per position, unit length (zero if it has no area)
  // The input's faces in the same order (a face keeps its index, so
  // per-face data still lines up), corners pointing at the copies.
  std::vector<Triangle> triangles;
  // For each copy (positions[V + i]), the input vertex it copies.
  std::vector<uint32_t> copied_from;
};

// Splits `mesh`'s vertex normals at edges whose two faces' normals are more
// than `crease_degrees` apart (>= 180: never split, one smooth normal per
// vertex). A vertex whose faces form one group keeps the mesh's own normal
// when the mesh has one per vertex, else gets the area-weighted normal of
// its faces (as compute_vertex_normals). Faces with no area neither join
// nor separate groups (they take the vertex's first copy). Faces whose orientations disagree
// (normals more than the angle apart) are split like a crease. Precondition: indices in range
// (validate_arrays). Cost: O(V + F log d), d the largest vertex degree.
ShadingMesh split_normals_at_creases(const Mesh& mesh, float crease_degrees);

// The angle the renderer uses for a user's `--crease` value: the value
// itself when it is on (> 0), else kDefaultShadingCreaseDegrees.
inline float shading_crease_degrees(float user_crease_degrees) {
  return user_crease_degrees > 0 ? user_crease_degrees : kDefaultShadingCreaseDegrees;
}

}  // namespace meshstream::client
