// Layered decimation (HCS, Li & Kuo 1998): each layer removes an independent
// set of interior vertices, least important first, and fills every hole with
// a fan from one of its ring vertices. The decoder restores layers in reverse
// order; within a layer the patches are disjoint, so any order works.
//
// Rules for a removal (checked against the mesh at the time of removal):
// - v is interior (boundary vertices are kept: the boundary and every
//   component survive unchanged), valence 3..kMaxRemovalValence;
// - v is not adjacent to a vertex removed earlier in the layer
//   (independence: stars are disjoint, so patches never overlap; two
//   removed vertices may share ring vertices);
// - the fan's diagonals are not existing edges (no non-manifold edge, genus
//   kept), and for valence 3 the new triangle is not already a face;
// - no fan triangle is degenerate on the grid (zero area, exact integers) or
//   turns against the star's normal (cosine <= kMinFanCosine).
// Among valid apexes the one whose worst fan triangle is the best shaped wins.
// Importance = distance of v from the least-squares plane of its star (area
// normal through the ring centroid) plus a small share of its distance from
// the ring average (the decoder's prediction), cheapest first.
#pragma once

#include <cstdint>
#include <vector>

#include "common/codec/editable_mesh.h"

namespace meshstream {

inline constexpr uint32_t kMaxRemovalValence = 16;

struct Removal {
  uint32_t vertex = 0;          // id in the input mesh
  std::vector<uint32_t> ring;   // ring[0] is the fan apex; CCW around vertex
  Vec3i position;
};

struct DecimationResult {
  // layers[0] was removed first (finest); the decoder restores the last first.
  std::vector<std::vector<Removal>> layers;
  std::vector<uint32_t> base_vertices;  // input ids of the vertices left, ascending
  std::vector<Triangle> base_faces;     // in input ids
};

struct DecimateOptions {
  uint32_t target_vertices = 300;  // stop once at most this many remain
  uint32_t max_layers = 200;
};

// Decimates `mesh` (consumed). Never fails: a mesh with nothing removable
// yields zero layers. O(V log V) per layer.
DecimationResult decimate_layers(EditableMesh mesh, const DecimateOptions& options);

}  // namespace meshstream
