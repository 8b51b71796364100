// Plane-record grouping: the vertex ids whose positions are still coarse
// are refined in groups (runs of consecutive ids, about a record's worth of
// plane bits each), one plane step of a whole group per plane record. The
// schedule (record_schedule.h) picks the group with the best estimated
// distortion drop per byte, so this file keeps each group's pending steps
// and the drop its next plane would bring.
#pragma once

#include <cstddef>
#include <cstdint>

#include "common/codec/distortion_estimate.h"
#include "common/codec/embedded_geometry.h"
#include "common/codec/refinement_codec.h"

namespace meshstream {

// A run of vertex ids refined together by plane records (a batch).
struct PlaneGroup {
  uint32_t first = 0, count = 0;
  bool started = false;    // a plane record was written for it
  uint32_t pending = 0;    // vertices with shift > 0
  int top_plane = 0;       // largest shift - 1 among them
  double scaled_drop = 0;  // estimated drop of its next plane x vertex count
};

// Recomputes g's pending count, top plane and the drop of its next plane
// step from the state (which it does not change) and the truth (whose
// surface-distance cache it fills). O(g.count) error evaluations.
void evaluate_group(const RefinementState& s, EncoderTruth& t, PlaneGroup& g);

// A plain coder for plane bits, the comparison EncodeReport::plane_bytes_plain
// measures: one adaptive model per plane and one for signs, persisting across
// records like the context models.
struct PlainPlaneModels {
  BitModel bit[kMaxShift + 1];
  BitModel sign;
};

// Bytes of the next plane step of vertices [first, first + count) through
// the plain coder (the state is not changed; `models` learn).
size_t plain_plane_bytes(const RefinementState& s, const EncoderTruth& t, uint32_t first,
                         uint32_t count, PlainPlaneModels& models);

}  // namespace meshstream
