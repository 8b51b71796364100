// Uniform quantization of positions to an integer grid over the bounding box.
//
// With `bits` b, each axis is split into 2^b - 1 equal steps of the box's
// LARGEST extent (one step size for all axes, so the grid is isotropic and
// distances stay comparable), the box minimum maps to 0. Integer positions
// are what the codec works on: decimation, prediction and residuals are exact
// integer arithmetic, so decoding reproduces the grid points bit for bit.
#pragma once

#include <cstdint>
#include <vector>

#include "common/base/result.h"
#include "common/mesh/mesh.h"
#include "common/mesh/vec.h"  // Vec3i: grid points

namespace meshstream {

struct QuantGrid {
  BoundingBox bounds;  // as stored in the stream header (floats)
  int bits = 12;
  // Step between grid points (0 for a box of zero extent).
  double step() const;
  int32_t max_coordinate() const { return (int32_t(1) << bits) - 1; }
  Vec3i quantize(Vec3f p) const;
  Vec3f dequantize(Vec3i q) const;
};

inline constexpr int kMinQuantBits = 8;
inline constexpr int kMaxQuantBits = 20;

// The grid over `mesh`'s bounding box. kInvalidArgument for bits outside
// 8..20; kInvalidMesh for non-finite coordinates. O(V).
Result<QuantGrid> make_grid(const Mesh& mesh, int bits);

// Every position snapped to the grid. O(V).
std::vector<Vec3i> quantize_positions(const Mesh& mesh, const QuantGrid& grid);

}  // namespace meshstream
