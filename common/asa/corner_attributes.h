// Per-corner attributes through subdivision (seams stay seams), used by
// subdivide_into (the client asks has_corner_data to pick its path).
//
// Every new vertex of a level is made on an edge (a, b) of the level
// before, and every output face descends from one input face (its source).
// So each output corner has barycentric coordinates in its source face,
// found from the new vertices' parents, and its value is the source face's
// corner values mixed by them: a new vertex on a seam edge gets, in the
// faces on either side, the values of that side's corners, so the seam
// stays where it was and nothing is smeared across it. Texture coordinates
// and colours are interpolated linearly (as the per-vertex ones are);
// per-corner normals are interpolated and renormalized (hard edges stay
// hard; per-vertex normals are recomputed from the subdivided surface).
#pragma once

#include <cstdint>
#include <vector>

#include "common/mesh/mesh.h"

namespace meshstream::asa {

// True when `mesh` has anything per corner or per face to carry.
inline bool has_corner_data(const Mesh& mesh) {
  return !mesh.corner_normals.empty() || !mesh.corner_colors.empty() ||
         !mesh.corner_texcoords.empty() || !mesh.face_materials.empty();
}

// Fills `out`'s corner attributes and face materials from `input`'s:
// `source[g]` is the input face output face g descends from, `parents`
// holds for every vertex id >= input.vertex_count() its two parent
// vertices at 2 id and 2 id + 1. Output corners get values of their own
// (`corners` is 0, 1, 2, ...). O(output corners * 2^levels).
void carry_corner_attributes(const Mesh& input, const std::vector<uint32_t>& source,
                             const std::vector<uint32_t>& parents, Mesh& out);

}  // namespace meshstream::asa
