// Applying a refinement record to the state: the decoder side of the
// structure records (the encoder's writer is encoder.cpp), dispatching plane
// records to plane_record.h.
#pragma once

#include <cstdint>
#include <span>

#include "common/base/result.h"
#include "common/codec/refinement_state.h"

namespace meshstream {

// Decodes one refinement record and applies it to `state`. Every count,
// index and symbol is range-checked, so bad bytes never read or write out of
// bounds and never make a non-manifold mesh; on error `state` is left
// half-applied and must be discarded (IncrementalDecoder keeps its output
// mesh, updated only after a record succeeds, and stops there).
// O(record size + touched faces).
// `expected_vertices`/`expected_faces` are the index's counts after the
// record; a mismatch is an error (and rolls back) like any other.
// Plane records (flag kRecordPlane) are dispatched to apply_plane_record.
Status apply_refinement_record(RefinementState& state, std::span<const uint8_t> payload,
                               uint32_t expected_vertices, uint32_t expected_faces,
                               AppliedRecord& applied);

}  // namespace meshstream
