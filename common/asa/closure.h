// Conforming closure of ASA targets with red-green rules (Cheang 1998;
// red-green refinement as in Bank, Sherman, Weiser 1983).
#pragma once

#include <cstdint>
#include <vector>

#include "common/asa/level_mesh.h"

namespace meshstream::asa {

// What the split step does with each face of the level.
enum FaceAction : uint8_t {
  kKeep = 0,    // copied unchanged
  kBisect = 1,  // exactly one edge split: two green halves
  kRed = 2,     // all three edges split: four triangles
  kOpened = 3,  // a green half whose pair is merged back into its parent,
                // which is split 1-to-4 (both halves carry this action)
};

struct ClosureBuffers {
  std::vector<uint8_t> action;      // per face, FaceAction
  std::vector<uint8_t> edge_split;  // per corner: the faced edge gets a new vertex
  std::vector<uint32_t> worklist;
};

// Closes the set of targets (target[f] != 0) into a conforming refinement:
//  * a target is split 1-to-4 (red);
//  * a face with one split edge is bisected (green); with two or three it
//    becomes red itself, which splits its remaining edges;
//  * a green half is never split or bisected again: if it is a target or
//    any of its outer edges is split, its pair is opened (merged back into the
//    parent, which is split 1-to-4 using the existing midpoint).
// Propagates with a worklist until stable. O(F + affected faces).
// Returns the number of split edges.
uint32_t close_targets(const LevelView& mesh, const uint8_t* target, ClosureBuffers& out);

// Local corners (0..2) of a green half whose edges are outer edges of the
// pair; the third is the internal edge A-M. first = (A, B, M): BM is faced by
// corner 0, AB by corner 2; second = (A, M, C): MC by 0, CA by 1.
inline bool green_outer_corner(uint8_t kind, uint32_t local) {
  return kind == kGreenFirst ? local != 1 : local != 2;
}

}  // namespace meshstream::asa
