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
// - kBaseCoderTraversal (encoder version 9 on): faces breadth first across
//   edges, one bit per open edge, the third corner named as new, as the
//   closing of an open fan, or by index; new positions parallelogram-
//   predicted; all through the adaptive range coder
//   (base_traversal_coder.cpp). Exact for any oriented manifold base,
//   including what Draco cannot carry (faces folded flat, vertices sharing
//   a grid point); used when Draco is bigger or not exact. It numbers the
//   vertices in order of first appearance, which the encoder adopts.
// - kBaseCoderOwn (encoder versions up to 8; still read): counts, positions
//   as per-axis deltas and face indices as deltas (about 72 bits per vertex
//   on a 49k-vertex base, 4-5x Draco).
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

struct TraversalCodedBase {
  std::vector<uint8_t> bytes;
  BaseMesh decoded;               // what decode_base_traversal gives back
  std::vector<uint32_t> to_base;  // decoded vertex -> vertex of the input base
};
// kUnsupported when `base` is not an oriented manifold (a directed edge in
// two faces, a face repeating a vertex). O(base size).
Result<TraversalCodedBase> encode_base_traversal(const BaseMesh& base, int quant_bits);
Result<BaseMesh> decode_base_traversal(std::span<const uint8_t> bytes, uint32_t vertex_count,
                                       uint32_t face_count, int quant_bits);

// Draco bytes for the base, or an error when Draco refuses it.
Result<std::vector<uint8_t>> encode_base_draco(const BaseMesh& base);
Result<BaseMesh> decode_base_draco(std::span<const uint8_t> bytes, uint32_t vertex_count,
                                   uint32_t face_count, int quant_bits);

// Whether the decoder reads base records of this coder id.
bool known_base_coder(uint8_t coder);
// Record 0 through the coder the header names (known_base_coder).
Result<BaseMesh> decode_base(uint8_t coder, std::span<const uint8_t> bytes, uint32_t vertex_count,
                             uint32_t face_count, int quant_bits);

}  // namespace meshstream
