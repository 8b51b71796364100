// Modified Butterfly edge points (Zorin, Schröder, Sweldens, "Interpolating
// subdivision for meshes with arbitrary topology", SIGGRAPH 1996), with the
// boundary and boundary-touching rules of OpenMesh's ModifiedButterFlyT and a
// crease extension (a crease is treated like a boundary on each side).
// Details and every deviation: butterfly_stencils.cpp.
#pragma once

#include <cstdint>
#include <vector>

#include "common/asa/level_mesh.h"

namespace meshstream::asa {

// Precomputed weights: tension omega for the ten-point stencil and the
// extraordinary-vertex weights s_j for every valence K up to max_valence.
class ButterflyWeights {
 public:
  // O(max_valence^2) once; grows on demand through ensure().
  void configure(float tension, uint32_t max_valence);
  void ensure(uint32_t max_valence);

  float tension() const { return tension_; }
  // s_0 .. s_{K-1} for valence K (K >= 3), then the centre weight at [K].
  const float* extraordinary(uint32_t K) const { return table_.data() + offset_[K]; }
  uint32_t max_valence() const { return max_valence_; }

 private:
  float tension_ = 0;
  uint32_t max_valence_ = 0;
  std::vector<float> table_;
  std::vector<uint32_t> offset_;
};

enum class EdgePlacement {
  kZorin,       // weights applied to 3-D points
  kProjection,  // only the normal component of the Butterfly offset (thesis)
};

// The new point of the edge faced by corner c of `mesh`. Deterministic and
// independent of corner numbering: both sides of an edge give the same bits
// (the stencil is always walked from intrinsic starting points and summed in
// symmetric pairs), so patches computed at different times agree.
// Preconditions: c < 3 * face_count, weights.max_valence() >= every valence
// of a non-feature vertex. O(1) for regular edges, O(K) otherwise.
Vec3f butterfly_point(const LevelView& mesh, uint32_t c, const ButterflyWeights& weights,
                      EdgePlacement placement);

// The neighbour of vertex(next(c)) along its other feature edge, walking away
// from the edge faced by c; kNone when that vertex is a corner (not exactly
// two feature edges). Exposed for the crease tests.
uint32_t other_feature_neighbor_at_next(const LevelView& mesh, uint32_t c);

}  // namespace meshstream::asa
