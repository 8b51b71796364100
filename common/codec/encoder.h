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
};

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
