// A fast corner-table builder for the subdivision hot path. Adjacency::build
// (common/mesh/adjacency.h) answers every query a tool needs; subdivision only
// needs the opposite corners, rebuilt for every call the client makes, so
// this builder trades generality for speed: half-edges are bucketed by their
// smaller vertex with the other end stored inline, so matching touches one
// small contiguous bucket per edge (details in corner_table.cpp). Same
// acceptance rules as Adjacency::build (tested against it).
#pragma once

#include <cstdint>
#include <vector>

#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream::asa {

struct CornerTableScratch {
  std::vector<uint32_t> offset;             // per vertex: first entry of its bucket
  std::vector<uint32_t> to, third, corner;  // per entry (corner grouped by vertex)
  std::vector<uint32_t> cursor;             // fill position per vertex
  std::vector<uint32_t> order, permuted;    // large fans only
  std::vector<uint8_t> visited;             // large fans only
};

// Fills opposite[c] (kNone on a boundary) for the mesh's 3F corners.
// Preconditions: indices in range, no repeated vertex in a triangle (as
// validate_arrays checks). Fails with kNonManifold, naming the edge or
// vertex, when an edge has more than two faces, two faces use an edge in the
// same direction, or a vertex's faces form more than one fan.
// O(V + F) time; no allocation once the scratch has capacity.
Status build_opposites(const Mesh& mesh, std::vector<uint32_t>& opposite,
                       CornerTableScratch& scratch);
// Same, also filling across[c] = vertex of opposite[c] (kNone on a boundary),
// which the matching knows for free.
Status build_opposites(const Mesh& mesh, std::vector<uint32_t>& opposite,
                       std::vector<uint32_t>& across, CornerTableScratch& scratch);

// After a successful build_opposites: the number of faces around each vertex
// (the valence of an interior vertex), read from the buckets. O(V).
void faces_per_vertex(const CornerTableScratch& scratch, std::vector<uint32_t>& faces);

}  // namespace meshstream::asa
