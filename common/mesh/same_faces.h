// Faces with the same vertex set (either orientation), found in linear time:
// the duplicate-face rules of import (clean.cpp) and of the statistics
// (topology.cpp) share it.
#pragma once

#include <cstdint>
#include <vector>

#include "common/mesh/mesh.h"

namespace meshstream {

// For every face, the first face (lowest index) with the same vertex set;
// the face itself when it is the first. kNone (adjacency.h's 0xFFFFFFFF) for
// a face with an index out of range. Faces are bucketed by their smallest
// vertex (a counting sort), and each bucket, a handful of faces, is sorted by
// the other two: O(V + F) time, 4 bytes per vertex and 8 per face, instead of
// a sort of 12-byte keys over the whole mesh.
std::vector<uint32_t> first_face_with_same_vertices(const Mesh& mesh);

}  // namespace meshstream
