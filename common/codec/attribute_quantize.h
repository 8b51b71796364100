// Quantization of the attributes the codec models (docs/hcs-format.md,
// "Attribute records"): one grid per attribute for the whole mesh.
// - Normals: octahedral (as Draco): the unit vector projected onto the
//   octahedron |x|+|y|+|z| = 1, the lower half folded up, two integer
//   coordinates in [0, 2^bits - 1].
// - Texture coordinates: one step for both axes over the values' box,
//   step = largest extent / (2^bits - 1), as the positions' grid.
// - Colours: the fixed grid [0, 1] with 2^bits - 1 steps per channel, so an
//   8-bit colour (k / 255) comes back exactly at 8 bits.
// Decoded values are what these functions give; an exact decoder reproduces
// them bit for bit (tests compare against them).
#pragma once

#include <array>
#include <cstdint>

#include "common/mesh/vec.h"

namespace meshstream {

inline constexpr int kMinAttributeBits = 2;
inline constexpr int kMaxAttributeBits = 16;

// Octahedral coordinates of `n` (any length; a zero vector maps to +z).
std::array<int32_t, 2> quantize_normal(Vec3f n, int bits);
// The same for a direction given in doubles (the geometric prediction).
std::array<int32_t, 2> quantize_direction(double x, double y, double z, int bits);
// The unit normal of octahedral coordinates.
Vec3f dequantize_normal(std::array<int32_t, 2> q, int bits);

struct TexcoordGrid {
  Vec2f min{0, 0};
  double step = 1;  // > 0
  int bits = 12;
};
TexcoordGrid make_texcoord_grid(const Vec2f* values, size_t count, int bits);
std::array<int32_t, 2> quantize_texcoord(const TexcoordGrid& grid, Vec2f t);
Vec2f dequantize_texcoord(const TexcoordGrid& grid, std::array<int32_t, 2> q);

// One colour channel (clamped to [0, 1]).
int32_t quantize_color_channel(float c, int bits);
float dequantize_color_channel(int32_t q, int bits);

}  // namespace meshstream
