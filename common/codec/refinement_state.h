// The state encoder and decoder keep while layers are restored: the mesh
// being refined, the order list the walk follows, every vertex's layer,
// valence and successive-approximation geometry, and the symbol models. Both
// sides change it through the same functions (patch_geometry.h,
// plane_record.h) so they cannot drift.
#pragma once

#include <cstdint>
#include <vector>

#include "common/base/result.h"
#include "common/codec/editable_mesh.h"
#include "common/codec/embedded_geometry.h"
#include "common/codec/stream_format.h"
#include "common/codec/structure_models.h"

namespace meshstream {

struct RefinementState {
  EditableMesh mesh;
  // Per vertex, together because the walk touches all three at once (one
  // cache line instead of three): the next vertex in the order list (kNone
  // ends it), the layer that inserted it (0 for the base) and its valence,
  // kept up to date by apply_patch.
  struct VertexEntry {
    uint32_t next = kNone;
    uint32_t layer = 0;
    uint32_t valence = 0;
    uint32_t taken = 0;  // faces holding a vertex of layer `taken_layer`
    uint32_t taken_layer = 0;
  };
  std::vector<VertexEntry> vertices;
  // Dense copies of what the decoder reads for every ring vertex of every
  // apex, small enough to stay in cache on meshes of 100k vertices where
  // `vertices` (20 bytes a vertex) and `geometry` (28) are not: reading
  // geometry[v].shift there cost ~9 % of a decode in cache misses.
  // vertex_layer[v] == vertices[v].layer (appended by apply_patch, never
  // changed; mark_taken_faces); vertex_shift[v] == geometry[v].shift, kept
  // in step by every function here that changes it (from_coarse_base,
  // apply_patch, the plane records; insertion_shift).
  std::vector<uint32_t> vertex_layer;
  std::vector<uint8_t> vertex_shift;
  uint32_t order_head = kNone;
  uint32_t layer = 0;       // layers started so far
  uint32_t cursor = kNone;  // next vertex of the walk
  int32_t max_coordinate = 4095;
  uint32_t last_count = 0;  // patches at the previous walk vertex
  RefinementModels models;
  // Successive-approximation state of every vertex (embedded_geometry.h);
  // mesh.positions() holds reconstruct() of each entry.
  std::vector<VertexGeometry> geometry;
  GeometryModels geometry_models;
  // The stream's refinement record format (header extra[0], stream_format.h);
  // both coders set it before the first record.
  RefinementFormatInfo format;

  // Starts from a base mesh (vertices in base order). Errors as EditableMesh::build.
  static Result<RefinementState> from_base(std::vector<Vec3i> positions,
                                           std::vector<Triangle> faces, int quant_bits);
  // Same from the coarse base points of an embedded stream: vertex v starts
  // at coarse[v] << base_shift with its low base_shift bits unknown.
  static Result<RefinementState> from_coarse_base(const std::vector<Vec3i>& coarse,
                                                  std::vector<Triangle> faces, int quant_bits,
                                                  int base_shift);
};

// What one record changed: the decoder's output (IncrementalDecoder turns it
// into a RecordDelta).
struct AppliedRecord {
  // False: the lists stay empty (a decoder that keeps no output mesh needs
  // no record of what changed; they would grow with the mesh).
  bool record_changes = true;
  std::vector<uint32_t> added_vertices;
  std::vector<uint32_t> touched_faces;
  std::vector<uint32_t> moved_vertices;  // plane records: positions that changed
};

}  // namespace meshstream
