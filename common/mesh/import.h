// Reading mesh files: Draco .drc through Draco's io; OBJ,
// OFF, PLY and STL (binary and ASCII) through our own readers (Draco has no OFF or ASCII
// STL reader, its PLY reader merges equal positions and drops texture
// coordinates, and its OBJ reader corrupts the heap on malformed corners —
// see mesh_readers.h). Import cleans the mesh into what the
// codec and ASA need and reports every change it made.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/base/result.h"
#include "common/mesh/file_contents.h"
#include "common/mesh/mesh.h"

namespace meshstream {

// What import changed, so `meshstream info` can show it: repairs are
// visible, never silent.
struct CleanReport {
  uint32_t vertices_in_file = 0;
  uint32_t faces_in_file = 0;          // triangles after fan-triangulating polygons
  uint32_t welded_vertices = 0;        // merged because bit-identical positions
  uint32_t degenerate_faces = 0;       // dropped (or kept: ImportOptions): a repeated vertex
  uint32_t duplicate_faces = 0;        // dropped: same vertex set as an earlier face
  uint32_t unreferenced_vertices = 0;  // dropped
  uint32_t nonmanifold_edges = 0;      // found (edges with more than two faces)
  uint32_t nonmanifold_vertices = 0;   // found (vertices joining several fans)
  uint32_t split_vertices = 0;         // copies added by the non-manifold repair
  uint32_t detached_faces = 0;         // faces given their own copies of an edge's vertices
  uint32_t flipped_faces = 0;          // re-oriented to make orientation consistent
  // Dropped after repair: the kept copy of a duplicated face (nearly always a
  // face and its reverse: a double-sided triangle) that repair had to cut
  // loose on every edge — a flap, not part of the surface. Vertex copies made
  // only for flaps are not counted in split_vertices; original vertices only
  // flaps used are counted in unreferenced_vertices.
  uint32_t double_sided_flaps = 0;
  // Everything else worth telling, e.g. "normals dropped: they differ
  // between corners of one vertex (per-face normals)".
  std::vector<std::string> notes;
  bool changed() const;
};

struct ImportOptions {
  // Weld vertices with bit-identical positions (OBJ and STL split them).
  bool weld = true;
  // Repair non-manifold edges and vertices by splitting vertices, so the
  // result is manifold. When false, import refuses such meshes with
  // kNonManifold and a message naming the first offending edge or vertex.
  bool repair_nonmanifold = true;
  // Drop faces with the same vertex set as an earlier face (the codec needs
  // them gone). Off only for analysis.
  bool drop_duplicate_faces = true;
  // Analysis mode (`meshstream info`, manifest tests): stop after welding and
  // dropping degenerate/unreferenced parts; non-manifold edges and vertices
  // are counted in the report but neither repaired nor refused.
  bool keep_nonmanifold = false;
  // With keep_nonmanifold only (distances, `meshstream compare`): keep faces
  // that repeat a vertex, after welding too, instead of dropping them. A
  // triangle that quantization folded to a segment or a point is still
  // surface there: its segment or point is measured, so a folded component
  // does not look missing. degenerate_faces then counts them, kept.
  bool keep_degenerate_faces = false;
  // After repair, drop flaps left by double-sided triangles (see
  // CleanReport::double_sided_flaps) instead of keeping each as a separate
  // one-triangle component.
  bool drop_double_sided_flaps = true;
};

struct ImportedMesh {
  Mesh mesh;
  CleanReport report;
  FileContents contents;  // what the file holds, including what import did not keep
};

// Reads and cleans `path`. Errors name the file and the problem: unreadable
// file (kIo), unknown format or malformed content (kParse), NaN/Inf
// coordinates, out-of-range indices or no usable triangle (kInvalidMesh),
// non-manifold when repair is off (kNonManifold). Never crashes on bad input.
// Cleaning, in this order (clean_mesh): weld bit-identical positions; drop
// faces with a repeated vertex; drop duplicate faces (same vertex set, first
// kept); drop unreferenced vertices; then, unless the mesh already is one,
// make it a consistently oriented manifold (manifold_repair.h: faces are never
// dropped — vertices are split, faces that cannot stay on an edge are
// detached, faces are flipped); finally drop double-sided flaps the repair
// cut loose (option drop_double_sided_flaps). Vertex order is the file's, minus what was
// dropped, plus repair copies appended at the end. Cost: O(V + F) (welding
// by hashing, duplicates and edges by per-vertex buckets: no sort over the
// whole mesh) plus parsing. The edge groups are built once and updated in
// place by the repair; each repair round (2-3 on real data) adds one
// union-find over the corners and sequential passes over the groups.
Result<ImportedMesh> import_mesh(const std::string& path, const ImportOptions& options = {});

// The cleaning step alone, on a mesh already in memory (same rules as import).
Result<CleanReport> clean_mesh(Mesh& mesh, const ImportOptions& options = {});

// Drops the vertices no face uses (per-vertex arrays follow, the others keep
// their order); returns how many. O(V + F).
uint32_t drop_unreferenced(Mesh& mesh);

}  // namespace meshstream
