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

#include "common/asa/level_mesh.h"
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

// The corner of face f at vertex v (v must be one of f's corners).
inline uint32_t corner_at(const Mesh& mesh, uint32_t f, uint32_t v) {
  const Triangle& t = mesh.triangles[f];
  return 3 * f + (t[0] == v ? 0u : t[1] == v ? 1u : 2u);
}

// How many faces of v's fan a walk from face `first` reaches across v's
// edges, entering only faces `enter(f)` accepts: forward (across the edge
// faced by next(corner)), then, unless that closed the loop, backward from
// `first`. At most `limit` steps each way (v's face count bounds a fan).
// The faces around v are one fan of accepted faces exactly when the count
// equals their number: LiveCornerTable checks a vertex's whole fan this
// way, the incremental subdivider the part of it inside its region.
template <class Enter>
size_t faces_reached_around(const Mesh& mesh, const uint32_t* opposite, uint32_t v, uint32_t first,
                            size_t limit, Enter&& enter) {
  const uint32_t start = corner_at(mesh, first, v);
  size_t reached = 1;
  uint32_t c = start;
  for (size_t step = 0; step < limit; ++step) {
    const uint32_t o = opposite[next_corner(c)];
    if (o == kNone || !enter(o / 3)) break;
    c = corner_at(mesh, o / 3, v);
    if (c == start) return reached;  // closed: the forward walk saw the whole loop
    ++reached;
  }
  c = start;
  for (size_t step = 0; step < limit; ++step) {
    const uint32_t o = opposite[prev_corner(c)];
    if (o == kNone || !enter(o / 3)) break;
    c = corner_at(mesh, o / 3, v);
    ++reached;
  }
  return reached;
}

// The level-0 adjacency of a mesh that changes a record at a time (the
// client's decoded mesh): opposite corners and the faces around every
// vertex, brought up to date with the faces a record created or rewrote
// instead of being rebuilt, so an update costs what it changed. After every
// apply() it equals build_opposites on the new mesh (tested), with the same
// acceptance rules for the faces it touched.
class LiveCornerTable {
 public:
  // From scratch. O(V + F).
  Status rebuild(const Mesh& mesh);
  // `mesh` differs from the last rebuild()/apply() mesh by the faces in
  // `changed`: created (index at or past the old face count) or rewritten
  // (old_corners[i] holds changed[i]'s previous corners; ignored for created
  // faces), plus vertices appended. Faces never disappear (fewer faces:
  // call rebuild). Repeats in `changed` are ignored after the first.
  // Positions do not matter. kNonManifold, naming the edge or vertex, when
  // a touched edge gets more than two faces or two faces in the same
  // direction, or a touched vertex's faces form more than one fan; the
  // table must then be rebuilt before use. O(changed faces x valence).
  Status apply(const Mesh& mesh, const std::vector<uint32_t>& changed,
               const std::vector<Triangle>& old_corners);

  const std::vector<uint32_t>& opposite() const { return opposite_; }
  const std::vector<uint32_t>& faces_around(uint32_t v) const { return vertex_faces_[v]; }
  uint32_t face_count() const { return static_cast<uint32_t>(opposite_.size() / 3); }
  uint32_t vertex_count() const { return static_cast<uint32_t>(vertex_faces_.size()); }

 private:
  Status link_corner(const Mesh& mesh, uint32_t c);
  Status check_fan(const Mesh& mesh, uint32_t v) const;

  std::vector<uint32_t> opposite_;
  std::vector<std::vector<uint32_t>> vertex_faces_;
  std::vector<uint32_t> face_stamp_, vertex_stamp_;
  uint32_t generation_ = 0;
  std::vector<uint32_t> relink_, fan_vertices_;
  CornerTableScratch scratch_;
};

}  // namespace meshstream::asa
