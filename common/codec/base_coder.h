// Coding the base mesh (record 0 of an `.hcs` stream).
//
// Two coders, id in the stream header (`base_coder`, stream_format.h):
// - kBaseCoderDraco: Draco's edgebreaker with the positions given to Draco as
//   INT32 grid coordinates, so Draco's integer prediction path codes them
//   losslessly (no Draco quantization at all): exact by construction. Draco
//   may reorder vertices and faces; the encoder adopts the order Draco's
//   decoder produces, so both sides start from the same base. The encoder
//   verifies every Draco result (same faces, same positions, nothing dropped:
//   Draco's encoder drops degenerate faces and may merge points) and falls
//   back to the own coder when it differs.
// - kBaseCoderOwn: our own simple coder: counts, positions as per-axis
//   deltas and face indices as deltas, all through the adaptive range coder.
//   Always exact; used when Draco is bigger or not exact.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "common/base/result.h"
#include "common/codec/quantize.h"
#include "common/codec/stream_format.h"
#include "common/mesh/mesh.h"

namespace meshstream {

struct BaseMesh {
  std::vector<Vec3i> positions;
  std::vector<Triangle> faces;
};

std::vector<uint8_t> encode_base_own(const BaseMesh& base);
// kCorrupt/kLimit on bad bytes; counts are checked against the header's.
Result<BaseMesh> decode_base_own(std::span<const uint8_t> bytes, uint32_t vertex_count,
                                 uint32_t face_count, int quant_bits);

// Draco bytes for the base, or an error when Draco refuses it.
Result<std::vector<uint8_t>> encode_base_draco(const BaseMesh& base);
Result<BaseMesh> decode_base_draco(std::span<const uint8_t> bytes, uint32_t vertex_count,
                                   uint32_t face_count, int quant_bits);

}  // namespace meshstream
