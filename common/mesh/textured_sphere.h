// A procedural textured model for tests and benchmarks while no imported
// model carries textures: a UV sphere whose texture coordinates have seams
// (the meridian where u wraps from 1 to 0, and the poles, where every
// triangle has its own u), one material and a generated PNG image.
#pragma once

#include <cstdint>
#include <vector>

#include "common/mesh/mesh.h"

namespace meshstream {

// A checkerboard of `cells` x `cells` squares in four saturated colours
// (red, green, blue, yellow, by quadrant of the image) with a light grid,
// `side` x `side` pixels, as PNG bytes (stb_image_write). Deterministic.
std::vector<uint8_t> make_checker_png(uint32_t side, uint32_t cells = 8);

// A unit sphere: 2 poles and (rings - 1) * segments welded vertices (closed,
// manifold, counter-clockwise from outside); texture coordinates per
// corner (corner_texcoords) over a (segments + 1) x (rings + 1) grid, so
// the seam vertices carry two values; material 0 uses texture 0, a
// checker of `texture_side` pixels. rings >= 2, segments >= 3. O(faces).
Mesh make_textured_uv_sphere(uint32_t rings = 24, uint32_t segments = 48,
                             uint32_t texture_side = 256);

}  // namespace meshstream
