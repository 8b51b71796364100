// Flatness marking (Cheang 1998, section 3 of docs/algorithms.md) and
// crease tagging: which triangles ASA refines and which edges stay sharp.
#pragma once

#include <cstdint>
#include <vector>

#include "common/asa/level_mesh.h"
#include "common/asa/view.h"

namespace meshstream::asa {

// Unit normal of every face (zero for a degenerate face). O(F).
void compute_face_normals(const LevelView& mesh, std::vector<Vec3f>& normals);

// Per corner: 1 when the edge it faces is a boundary edge or bends by more
// than crease_degrees (angle between the two face normals); crease_degrees
// <= 0 tags boundaries only. Both corners of an edge get the same flag.
// Needs mesh.corner_vertex, opposite and positions. Returns the number of
// corners tagged. O(F).
uint32_t tag_feature_edges(const LevelView& mesh, float crease_degrees,
                           const std::vector<Vec3f>& normals, std::vector<uint8_t>& feature_edge);

// Per vertex: the number of feature edges at it (saturating at 255). O(F).
void count_vertex_features(const LevelView& mesh, std::vector<uint8_t>& vertex_features);

// Per vertex: the number of faces around it (the valence of an interior
// vertex). Returns the largest count. O(F).
uint32_t count_vertex_faces(const LevelView& mesh, std::vector<uint32_t>& faces);

// ASA targets: both faces of every interior, non-feature edge whose unit
// normals satisfy N1.N2 <= t become targets (the pair is flat when
// t < N1.N2 <= 1). Feature edges are sharp on purpose and ask for nothing.
// With `view` (view-dependent ASA, view.h), a bent edge marks its faces
// only where the camera says it matters on screen; the flatness rule itself
// is the same. Returns the number of targets. O(F).
uint32_t mark_targets(const LevelView& mesh, const std::vector<Vec3f>& normals, float t,
                      std::vector<uint8_t>& target, const ViewTest* view = nullptr);

// mark_targets after an adaptive split, testing only the edges of fresh faces
// (fresh[f] != 0): an edge between two unchanged faces was flat at the level
// before (else both would have been refined) and still is; with a camera,
// or the camera ruled it out and still does (same edge, same camera). Same
// targets as
// mark_targets (the dot product is symmetric bit for bit). Returns the number
// of targets. O(F) for the flags plus O(fresh faces).
uint32_t mark_targets_near_fresh(const LevelView& mesh, const std::vector<Vec3f>& normals,
                                 const std::vector<uint8_t>& fresh, float t,
                                 std::vector<uint8_t>& target, const ViewTest* view = nullptr);

}  // namespace meshstream::asa
