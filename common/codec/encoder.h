// Encoding a mesh into one progressive `.hcs` stream (container.h for the
// layout): quantize, decimate layer by layer, code the base mesh with Draco,
// then refinement records from coarse to fine.
#pragma once

#include <cstdint>
#include <vector>

#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream {

struct EncodeOptions {
  int quant_bits = 12;                 // 8..20, grid over the bounding box
  uint32_t target_base_vertices = 300; // stop decimating at about this many
  uint32_t record_bytes = 2048;        // close a refinement record at about this size
  bool allow_draco_base = true;        // false: always the own base coder (tests)
};

// Ids written in the stream header (`structure_coder`, `geometry_coder`).
inline constexpr uint8_t kStructureCoderRange = 1;  // adaptive binary range coder
inline constexpr uint8_t kGeometryCoderRangeAverage = 1;  // ring average + range-coded residual
inline constexpr uint8_t kRefinementFormat = 1;     // header extra[0]

// Bumped whenever the bytes an encoder writes for the same input change, so
// caches keyed by (content hash, encoder version) stay correct.
inline constexpr uint32_t kEncoderVersion = 1;

// Encodes a clean manifold mesh (see import.h). kInvalidArgument for bad
// options, kNonManifold / kInvalidMesh for a mesh the codec cannot take.
Result<std::vector<uint8_t>> encode_hcs(const Mesh& mesh, const EncodeOptions& options = {});

// The mesh an exact decoder must give back: positions snapped to the
// quantization grid (dequantized), same triangles.
Result<Mesh> quantized_reference(const Mesh& mesh, int quant_bits);

}  // namespace meshstream
