// Plane records: the bits of existing vertices' positions sent after their
// insertion, one bit plane a record (embedded_geometry.h for the steps).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "common/base/result.h"
#include "common/codec/refinement_state.h"

namespace meshstream {

// A plane record: u8 flags (kRecordPlane), varint first vertex, varint
// vertex count, then one range-coded block with one plane step
// (embedded_geometry.h) for every vertex of [first, first + count) whose
// shift is not 0. The range must lie inside the mesh. The record's positions
// go to the mesh and `applied.moved_vertices`. O(count).
Status apply_plane_record(RefinementState& state, std::span<const uint8_t> payload,
                          AppliedRecord& applied);
// Encoder of the same; `residuals[v - first]` is vertex v's true residual
// against its anchor (count of them). Applies the step to `state` as the
// decoder will.
std::vector<uint8_t> write_plane_record(RefinementState& state, uint32_t first, uint32_t count,
                                        std::span<const Vec3i> residuals);

}  // namespace meshstream
