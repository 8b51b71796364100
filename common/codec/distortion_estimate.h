// The encoder's distortion estimate: how much closer to the original the
// decoded mesh gets with each record, from what only the encoder knows
// (every vertex's true position). The record schedule (record_schedule.h)
// orders records by this estimate per byte. A vertex's error is either its
// displacement from its true position or (with the original surface in
// grid units) its distance to that surface; the estimate spreads it over
// the area around the vertex (docs/hcs-format.md, "Ordering").
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "common/codec/quantize.h"
#include "common/mesh/mesh.h"
#include "common/metrics/bvh.h"

namespace meshstream {

// What only the encoder knows about each decoder vertex: its true position
// (and residual against its anchor) and the weight of its error in the
// distortion estimate; and, by input id, unit normals of the original.
struct EncoderTruth {
  // The grid points by input id (the caller's, shared by every candidate),
  // and every decoder vertex's input id: its true position is
  // input_position[input_of[v]] (4 bytes a vertex instead of a copy of 12).
  std::span<const Vec3i> input_position;
  std::vector<uint32_t> input_of;
  // Its residual against its anchor is position(v) - the anchor (fixed
  // once the vertex is in: RefinementState::geometry).
  Vec3i position(uint32_t v) const { return input_position[input_of[v]]; }
  // Star area when the vertex got its geometry x sqrt(vertex count then):
  // the area its error spreads over shrinks as the mesh refines around it;
  // area(now) ~ weight / sqrt(vertices now) measured better than 1 / n
  // (refinement is not uniform: flat regions stay coarse) or no decay.
  std::vector<double> weight;
  // By input id; the same for every candidate, so computed once and shared.
  // Read only without a surface (the displacement estimate).
  std::span<const Vec3f> input_normal;
  // The original surface in grid units; when set, a vertex's error is its
  // distance to that surface instead of its displacement from its truth.
  const TriangleBvh* surface = nullptr;
  // Per vertex, the surface errors of the last two positions asked about
  // (a group's next plane is evaluated again when the group grows, and its
  // "after" becomes the next evaluation's "before"), and the hierarchy
  // slot found last, which starts the next search nearby
  // (TriangleBvh::closest_from_slot). A position is kept as its offset from
  // the vertex's true position, 10 bits an axis (offset_key in the .cpp); a
  // farther one is not kept and is searched again, with the same answer.
  // Packed to 4-byte alignment: 28 bytes an entry (issue 15's encoder
  // memory; 48 with whole positions, 40 with packed ones). Only lookups
  // and their cost depend on the cache: every answer is the exact query's.
#pragma pack(push, 4)
  struct CachedError {
    static constexpr uint32_t kNoKey = 0xffffffffu;
    uint32_t position[2] = {kNoKey, kNoKey};
    uint32_t slot = TriangleBvh::kNoHint;
    double error2[2] = {-1, -1};
  };
#pragma pack(pop)
  static_assert(sizeof(CachedError) == 28, "two offsets, a slot and two errors");
  std::vector<CachedError> cached;
};

// Squared error of a displaced vertex for the distortion estimate. The
// whole vector counts: weighting tangential slip down (it mostly slides the
// surface within itself) measured worse on CAD meshes, where a vertex on a
// crease slides across the other face.
double displacement_error2(Vec3i recon, Vec3i truth);

// Decoder vertex v's squared error when shown at `recon`: its distance to
// the original surface, or (no surface) its displacement from its true
// position. Surface answers are remembered (EncoderTruth::cached), so `t`
// changes. Precondition: v < t.input_of.size(). Cost: one closest-point
// query when the answer is not cached.
double vertex_error2(EncoderTruth& t, uint32_t v, Vec3i recon);

// Squared distance from `p` to the fan of `ring` (ring[0], ring[i], ring[i+1]):
// the faces a patch replaces. Infinite for a ring of fewer than 3 vertices.
double fan_distance2(const std::vector<Vec3i>& pos, const std::vector<uint32_t>& ring, Vec3i p);

// Area of the fan/star polygon `ring` (sum of triangle areas from ring[0]).
double ring_area(const std::vector<Vec3i>& p, const std::vector<uint32_t>& ring);

// Area-weighted vertex normals of the (quantized) input, unit length
// ((0, 0, 1) for a vertex without area). O(V + F).
std::vector<Vec3f> vertex_normals(const std::vector<Vec3i>& q, const std::vector<Triangle>& faces);

}  // namespace meshstream
