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
// extraordinary-vertex weights s_j for the valences that occur. Only valences
// present are tabulated (K + 1 floats each), so a fan with a huge valence
// costs O(K), not O(K^2).
class ButterflyWeights {
 public:
  // bound_offsets: every new point is kept within the offset bound of
  // butterfly_rules.h (no spikes, issue 20); off gives the plain rules.
  void configure(float tension, bool bound_offsets = true);
  // Adds the weights of every interior (feature-free) vertex's valence.
  // O(V) plus O(K) per new valence.
  void add_valences(const uint32_t* valence, const uint8_t* vertex_features, uint32_t vertex_count);
  // Same for the listed vertices only. O(list) plus O(K) per new valence.
  void add_valences(const uint32_t* valence, const uint8_t* vertex_features,
                    const std::vector<uint32_t>& list);
  // Same for vertices first .. first + count - 1.
  void add_valences(const uint32_t* valence, const uint8_t* vertex_features, uint32_t first,
                    uint32_t count);
  void add(uint32_t K);

  float tension() const { return tension_; }
  bool bounds_offsets() const { return bound_offsets_; }
  // s_0 .. s_{K-1} for valence K (K >= 3, added before), then the centre
  // weight at [K].
  const float* extraordinary(uint32_t K) const { return table_.data() + offset_[K]; }

 private:
  float tension_ = 0;
  bool bound_offsets_ = true;
  std::vector<float> table_;
  std::vector<uint32_t> offset_;  // per valence, kNone when absent
};

enum class EdgePlacement {
  kZorin,       // weights applied to 3-D points
  kProjection,  // only the normal component of the Butterfly offset (thesis)
};

// The new point of the edge faced by corner c of `mesh`. Deterministic and
// independent of corner numbering: both sides of an edge give the same bits
// (the stencil is always walked from intrinsic starting points and summed in
// symmetric pairs), so patches computed at different times agree.
// Preconditions: c < 3 * face_count, the weights hold every valence of a
// non-feature vertex. O(1) for regular edges, O(K) otherwise.
Vec3f butterfly_point(const LevelView& mesh, uint32_t c, const ButterflyWeights& weights,
                      EdgePlacement placement);

// The neighbour of vertex(next(c)) along its other feature edge, walking away
// from the edge faced by c; kNone when that vertex is a corner (not exactly
// two feature edges). Exposed for the crease tests.
uint32_t other_feature_neighbor_at_next(const LevelView& mesh, uint32_t c);

}  // namespace meshstream::asa
