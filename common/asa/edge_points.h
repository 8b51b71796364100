// All new edge points of one level in two passes: edges whose endpoints are
// regular (or on a boundary/crease) get their stencil directly; edges at an
// extraordinary vertex are computed around that vertex, which gathers its
// one-ring once and evaluates the K rotations of its stencil from that local
// copy (the per-edge way walks the fan again for every one of its K edges).
// Results are bit-identical to rules::edge_point. Uses mesh.across (derived
// when null).
// Internal to common/asa.
#pragma once

#include <cstdint>
#include <vector>

#include "common/asa/butterfly_stencils.h"
#include "common/asa/level_mesh.h"

namespace meshstream::asa {

struct EdgePointScratch {
  std::vector<uint32_t> vertex_corner;  // per vertex: a corner at it, kNone between calls
  std::vector<uint32_t> centres;        // extraordinary vertices met this call
  std::vector<uint32_t> pending;        // naming corners of edges done at their centres
  std::vector<uint32_t> across;         // only when the level has none
  std::vector<uint8_t> irregular;       // per vertex: an extraordinary centre
  std::vector<uint8_t> arrivals;        // per new vertex (minus first_new): stencils still expected
  std::vector<float> ring;         // one centre's one-ring (twice over) and sums, per coordinate
  std::vector<uint32_t> ring_ids;  // new vertex on each ring edge (or kNone)
  std::vector<uint32_t> ring_corners;  // the corner facing each ring edge
  // Fans of the extraordinary centres (corners in walk order), recorded by a
  // walk; after a uniform split the caller maps them to the child level
  // (map_fans_to_uniform_children) and the next call reads them instead of
  // walking (a chain of dependent loads per step).
  std::vector<uint32_t> fan_vertex, fan_start, fan_corner;
  bool fans_valid = false;
  bool record_fans = false;  // walked fans are recorded (set by the uniform split)
};

// For every corner c with edge_vertex[c] != kNone that names its edge
// (boundary, or c < opposite[c]): pos[edge_vertex[c]] = the Butterfly point of
// the edge faced by c. edge_vertex holds absolute vertex ids >= first_new for
// both corners of a split edge (kNone for the rest). Preconditions as
// butterfly_point. O(split edges + sum over extraordinary centres of K^2),
// the same order as the per-edge stencils.
// With `naming` (the corners naming the split edges, any order), only those
// corners are visited, each edge with its own stencil (rules::edge_point):
// O(split edges x valence) instead of O(corners + vertices).
// After a uniform 1-to-4 split (face 4f + i is the corner child at vertex i
// of f): every cached fan corner c moves to 12 (c / 3) + 3 (c % 3), the same
// vertex's corner in its corner child; the fans stay valid (old vertices keep
// their valence and order). O(cached corners).
void map_fans_to_uniform_children(EdgePointScratch& scratch);

void compute_edge_points(const LevelView& mesh, const uint32_t* edge_vertex, uint32_t first_new,
                         uint32_t new_count, const ButterflyWeights& weights,
                         EdgePlacement placement, Vec3f* pos, EdgePointScratch& scratch,
                         const std::vector<uint32_t>* naming = nullptr);

}  // namespace meshstream::asa
