// Layered decimation (HCS, Li & Kuo 1998): each layer removes an independent
// set of vertices, least important first, and fills every hole with
// a fan from one of its ring vertices. The decoder restores layers in reverse
// order; within a layer the patches are disjoint, so any order works.
//
// Rules for a removal (checked against the mesh at the time of removal):
// - valence 3..kMaxRemovalValence; a boundary vertex (at least two faces)
//   is removed along the boundary: the new boundary edge joins its two
//   boundary neighbours, so boundary loops and components survive (a
//   component never loses its last face: k-2 >= 1 faces remain);
// - v is not adjacent to a vertex removed earlier in the layer
//   (independence: stars are disjoint, so patches never overlap; two
//   removed vertices may share ring vertices);
// - no new edge (the fan's diagonals, and for a boundary vertex the new
//   boundary edge) already exists (no non-manifold edge; Euler characteristic
//   and boundary loops kept, so genus is kept), and for an interior valence-3
//   vertex the new triangle is not already a face;
// - no fan triangle with area turns against the star's normal (cosine <=
//   kMinFanCosine); a fan triangle folded flat on the grid (zero area, exact
//   integers) is allowed where a triangle of v's star is folded flat
//   already: it covers nothing and cannot turn over, and refusing it
//   stalled decimation on dense scans, where 12-bit positions fold many
//   triangles flat. A star with no area takes only fans without area.
// A fan from apex a is exactly the half-edge collapse of v into a, so the
// error is Garland & Heckbert's quadric (1997): every vertex carries the
// area-weighted planes of the original faces around it (and, weighted by
// squared length, planes through boundary edges perpendicular to their face,
// so boundaries keep their shape); removing v into a costs the mean squared
// distance of a from v's planes, and a inherits v's quadric. Among valid
// apexes the least error wins (shape breaks near-ties).
// Importance = log(1 + sqrt(e) + |v - ring average| / 20) + valence / 4,
// in grid units, where e is the quadric error of the chosen valid apex
// times the area v's quadric stands for over the mean vertex's (decimate.cpp:
// a removal's share of the squared surface RMS); the prediction term keeps
// residuals small,
// the valence term is a regularizer in the spirit of Alliez & Desbrun's
// valence-driven decimation (2001). Each layer draws its independent set,
// cheapest first, from the cheapest half of the candidates only, so
// important vertices stay for coarser layers.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "common/codec/editable_mesh.h"

namespace meshstream {

inline constexpr uint32_t kMaxRemovalValence = 16;

// 12 bytes a removal: its position is the input's (decimation moves no
// vertex: q[vertex]), its ring a range of its layer's ring pool. It was 40
// (a copy of the position and a span) and, before the pools, 48 plus a heap
// block; the layers are kept until the encode ends (issue 15's memory).
struct Removal {
  static constexpr uint16_t kInterior = 0xFFFF;

  uint32_t vertex = 0;      // id in the input mesh
  uint32_t ring_first = 0;  // its ring: DecimationLayer::rings[ring_first, + ring_size)
  uint16_t ring_size = 0;   // at most kMaxRemovalValence
  // kInterior for an interior vertex; for a boundary vertex the index i of
  // the ring edge (ring[i], ring[i+1]) that its removal turned into a
  // boundary edge.
  uint16_t open_edge = kInterior;

  // open_edge, kNone for an interior vertex.
  uint32_t open() const { return open_edge == kInterior ? kNone : open_edge; }
};
static_assert(sizeof(Removal) == 12);

// One layer: its removals and their rings (ring[0] is the fan apex; CCW
// around the vertex), back to back in one array.
struct DecimationLayer {
  std::vector<Removal> removals;
  std::vector<uint32_t> rings;

  std::span<const uint32_t> ring(const Removal& r) const {
    return {rings.data() + r.ring_first, r.ring_size};
  }
};

struct DecimationResult {
  // layers[0] was removed first (finest); the decoder restores the last first.
  std::vector<DecimationLayer> layers;
  std::vector<uint32_t> base_vertices;  // input ids of the vertices left, ascending
  std::vector<Triangle> base_faces;     // in input ids
};

// Measured on the bunny at a quarter of the stream against 1 (all
// candidates): RMS -30 %, Hausdorff -55 %, same size (1924a51); and against
// 2/3, 3/4 and 1 on every real mesh (bench/REPORT.md, "Layer size").
inline constexpr double kDefaultCandidateShare = 0.5;

struct DecimateOptions {
  uint32_t target_vertices = 300;  // stop once at most this many remain
  uint32_t max_layers = 200;
  // Each layer draws its independent set, cheapest first, from this share of
  // its candidates (by removal cost), all of them when none of that share is
  // removable; 0 < share <= 1. The share bounds a layer's size: at 0.5 a
  // layer removes about 14 % of the vertices (bench/REPORT.md, "Layer size").
  double candidate_share = kDefaultCandidateShare;
  // The base keeps at most this share of the vertices (never fewer than
  // kMinBaseTarget; 0 or >= 1: off), so a small mesh's base does not
  // outweigh its first refinements. Off, and not an EncodeOptions setting:
  // no share paid on the real meshes (docs/hcs-format.md, "Layers").
  double max_base_share = 0;
  // Threads for the removal costs: 0 = one per core. The result is the
  // same for every count.
  unsigned threads = 0;
  // Optional: called after each layer, from the calling thread, with the
  // share of the vertices above the target removed so far (0..1).
  std::function<void(double)> progress;
  // Optional: vertices never removed (locked[v] != 0), e.g. where an
  // attribute seam or a material border passes (attribute_layout.h): the
  // patches then never cross a seam. Empty = none locked.
  std::vector<uint8_t> locked;
  // Optional: called before each layer (0 = the first removed) to lock
  // more vertices for that layer only (`locked` comes sized to the mesh's
  // vertices, all 0): the locality experiment's cell borders
  // (locality_cells.h). Empty = none.
  std::function<void(uint32_t layer, const EditableMesh& mesh, std::vector<uint8_t>& locked)>
      layer_locks;
};

inline constexpr uint32_t kMinBaseTarget = 32;

// The number of vertices decimate_layers stops at for a mesh of `vertices`:
// min(target_vertices, max(kMinBaseTarget, max_base_share x vertices)).
uint32_t base_target(uint32_t vertices, const DecimateOptions& options);

// Decimates `mesh` (consumed) down to about base_target(vertices) vertices.
// Never fails: a mesh with nothing removable yields zero layers.
// O(V log V) per layer.
DecimationResult decimate_layers(EditableMesh mesh, const DecimateOptions& options);

}  // namespace meshstream
