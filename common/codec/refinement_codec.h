// Refinement records: the state both encoder and decoder keep while layers
// are restored, the adaptive models of the symbols, and the shared steps
// (patch resolution, prediction, insertion) so the two sides cannot drift.
//
// How a layer is described (HCS's "structure data", our own layout):
// the decoder walks the coarse vertices in the *order list* (base vertices in
// base order; every inserted vertex is linked right after the apex of its
// patch, so list neighbours are surface neighbours and a slice of the list is
// a spatially coherent batch). At each vertex u present before the layer it
// reads how many patches have their fan apex at u, and for each: k, the
// valence of the vertex to insert (the fan has k-2 faces), and which run of
// k-2 faces of u's star is the fan, as a rank among the runs that fit,
// ordered by how much they look like a fan (longest diagonals first: a fan
// over a removed vertex's hole has long edges from the apex; this saves a
// third of the bits of a plain star index); when ring edges
// of the patch lie on the boundary, which of them (if any) the vertex
// re-enters as a boundary vertex. Then the vertex's
// position as a residual from the prediction (average of the k ring vertices,
// HCS's neighbour average), per axis, through models chosen by the ring's
// size on the grid (bigger rings, bigger residuals).
//
// A record covers a run of the walk (a batch); the first record of a layer
// restarts the walk. Record payload: u8 flags (bit 0: starts a layer),
// varint walk steps, varint insertions, then one range-coded block.
// Format 3 (kRefinementFormat) keeps this layout and codes the same symbols
// through models that learn faster at first (BitModelV), with the valence
// also by the apex's free faces and the start rank by the number of
// candidate runs and the lead of the best (docs/hcs-format.md).
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "common/base/result.h"
#include "common/codec/editable_mesh.h"
#include "common/codec/embedded_geometry.h"
#include "common/codec/range_coder.h"
#include "common/codec/stream_format.h"

namespace meshstream {

inline constexpr int kScaleContexts = 20;

struct RefinementModels {
  BitTreeModel<2> patch_count[8 * 2 * 3 * 4];  // by count_context; 3 = escape
  AdaptiveUIntModel patch_count_extra;
  BitTreeModel<4> start_rank[6];  // by min(k - 3, 5); 15 = escape
  AdaptiveUIntModel start_rank_big;
  BitTreeModel<4> valence[13];  // k - 3 (k <= 18), by min(apex ring size, 12)
  AdaptiveIntModel residual[kScaleContexts][3];
  AdaptiveUIntModel open_edge;  // 0 interior vertex, i+1: re-enters boundary edge i
  // Format 3 codes the structure symbols (counts, valences, ranks, open
  // edges) through models whose adaptation slows as they learn (BitModelV),
  // with finer contexts for valences and start ranks (valence_model3,
  // start_rank_context). Residuals keep `residual` (BitModelV there saved
  // 0.2 % of the stream but cost 2-3 % of decode time), plane records
  // GeometryModels, in every format.
  bool v_models = false;  // format >= 3: use the models below (set by the coders)
  BitTreeModel<2, BitModelV> patch_count3[8 * 2 * 3 * 4];  // by count_context
  AdaptiveUIntModelV patch_count_extra3;
  BitTreeModel<4, BitModelV> valence3[13 * 8];        // by valence_model3
  BitTreeModel<4, BitModelV> start_rank3[6 * 3 * 4];  // by start_rank_context
  AdaptiveUIntModelV start_rank_big3;
  AdaptiveUIntModelV open_edge3;
};

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
  // Refinement record format (header extra[0]): 1 = issue I's records (no
  // shift field, no plane records), 2 = embedded geometry, 3 = the same
  // records through RefinementModels' format-3 models and contexts.
  uint8_t format = 2;

  // Starts from a base mesh (vertices in base order). Errors as EditableMesh::build.
  static Result<RefinementState> from_base(std::vector<Vec3i> positions,
                                           std::vector<Triangle> faces, int quant_bits);
  // Same from the coarse base points of an embedded stream: vertex v starts
  // at coarse[v] << base_shift with its low base_shift bits unknown.
  static Result<RefinementState> from_coarse_base(const std::vector<Vec3i>& coarse,
                                                  std::vector<Triangle> faces, int quant_bits,
                                                  int base_shift);
};

// One patch resolved against the current mesh.
struct ResolvedPatch {
  std::vector<uint32_t> ring;         // R_0 = apex, ..., R_k-1
  std::vector<uint32_t> fan_corners;  // k-2 corners at the apex
};

// Marks in `used` (one entry per face of u's star) the faces that hold a
// vertex inserted in the current layer: they belong to a patch already
// restored, so no fan can use them. Returns the number of free faces; a
// walk vertex with none cannot be an apex and codes nothing. O(faces).
uint32_t mark_taken_faces(const RefinementState& s, const std::vector<uint32_t>& star_ring,
                          uint32_t faces, std::vector<uint8_t>& used);

// The number of u's faces that hold no vertex inserted in the current layer,
// from counts apply_patch keeps (no swing around u needed). Equals what
// mark_taken_faces finds.
inline uint32_t free_face_count(const RefinementState& s, uint32_t u) {
  const RefinementState::VertexEntry& e = s.vertices[u];
  const uint32_t faces = e.valence - (s.mesh.is_boundary(u) ? 1 : 0);
  const uint32_t taken = e.taken_layer == s.layer ? e.taken : 0;
  return faces > taken ? faces - taken : 0;
}

// Context of the patch count at walk vertex u: its free faces (capped at
// 7), whether the previous walk vertex held patches, u's age in layers
// (1, 2, 3+) and its valence (<= 5, 6, 7-8, 9+).
inline uint32_t count_context(const RefinementState& s, uint32_t u, uint32_t free_faces) {
  const uint32_t age = std::min<uint32_t>(s.layer - s.vertices[u].layer, 3) - 1;
  const uint32_t val = std::min<uint32_t>(s.vertices[u].valence, 12);
  const uint32_t vb = val <= 5 ? 0 : val == 6 ? 1 : val <= 8 ? 2 : 3;
  return ((std::min<uint32_t>(free_faces, 7) * 2 + (s.last_count > 0 ? 1 : 0)) * 3 + age) * 4 + vb;
}

// Format 3's model of the patch count: count_context's, adapting by
// BitModelV. (Tried and dropped, no gain over 13 meshes: whether u has
// faces taken in this layer — never, the layers' removals are independent
// — the count two walk steps back, and the number of u's free faces whose
// two other vertices the walk has already visited, which only a patch at u
// could still use.)
inline BitTreeModel<2, BitModelV>& count_model3(RefinementState& s, uint32_t u,
                                                uint32_t free_faces) {
  return s.models.patch_count3[count_context(s, u, free_faces)];
}

// Format 3's model of k - 3 for a patch at apex u: by u's ring size (as
// format 2) and the free faces of u left for it (min 7; k - 2 of them
// become the fan, after the patches already read at u).
inline BitTreeModel<4, BitModelV>& valence_model3(RefinementState& s, uint32_t ring_size,
                                                  uint32_t free_left) {
  return s.models.valence3[std::min(ring_size, 12u) * 8 + std::min<uint32_t>(free_left, 7)];
}

// Format 3's context of a start rank: k, the number of candidate runs
// (1 codes nothing) and how far the best run's score leads the second's.
// (candidates 2, 3-4, 5+; best/second below 1.25, 2, 4, or more).
// Scores are sums of at most 15 squared grid lengths (< 2^46 at 20 bits):
// the products cannot overflow.
inline uint32_t start_rank_context(uint32_t k, size_t candidates, int64_t best, int64_t second) {
  const uint32_t kb = std::min(k - 3, 5u);
  const uint32_t cb = candidates <= 2 ? 0 : candidates <= 4 ? 1 : 2;
  const uint32_t gap = 4 * best < 5 * second ? 0
                       : best < 2 * second   ? 1
                       : best < 4 * second   ? 2
                                             : 3;
  return (kb * 3 + cb) * 4 + gap;
}

// Resolves the patch whose first fan face is star index r and whose vertex
// has valence k, given the apex's star. False when it does not fit (r or k
// out of range for the star, a fan crossing the boundary or wrapping onto
// itself). O(k).
bool resolve_patch(const EditableMesh& mesh, uint32_t apex, const std::vector<uint32_t>& star_ring,
                   const std::vector<uint32_t>& star_corners, uint32_t r, uint32_t k,
                   ResolvedPatch& out);

// Indices i of the patch's ring edges (R_i, R_i+1) that are boundary edges
// of the current mesh: where a removed boundary vertex may re-enter.
void patch_boundary_edges(const EditableMesh& mesh, const ResolvedPatch& patch,
                          std::vector<uint32_t>& out);

// The first-face indices r (into the apex's star) where a fan of k-2 faces
// fits and overlaps no face marked in `used`, best candidate first: by the
// sum of the squared lengths of the fan's diagonals (k >= 4) or of the
// edge opposite the apex (k = 3), larger first, ties by r. Integer-exact.
// O(faces * k).
void rank_patch_starts(const EditableMesh& mesh, uint32_t apex,
                       const std::vector<uint32_t>& star_ring, const std::vector<uint8_t>& used,
                       uint32_t k, std::vector<uint32_t>& out);

// The decoder's shortcut: the same as rank_patch_starts(...)[rank], or
// kNone when there are not more than `rank` candidates. Rank 0 (the common
// case) is one pass over the candidates instead of a sort. `scratch_starts`
// is working space kept by the caller (no allocation per call).
uint32_t select_patch_start(const EditableMesh& mesh, uint32_t apex,
                            const std::vector<uint32_t>& star_ring,
                            const std::vector<uint8_t>& used, uint32_t k, uint32_t rank,
                            std::vector<uint32_t>& scratch_starts);

// How a residual is modelled: `scale` (log2 of the ring's mean L1 edge
// length on the grid) picks the model set; the axes are taken in order of
// the ring normal's components, largest first (role 0 is the axis closest to
// the normal: its residual is the curvature offset, the other two are
// tangential slip), and role 0's sign is flipped when the normal points down
// that axis so "outward" is always the same symbol. Integer-exact: the
// normal is a sum of integer cross products.
struct ResidualContext {
  int scale = 0;
  int axis[3] = {0, 1, 2};
  bool flip = false;
};
// What both sides know of a vertex inserted into `ring` before its
// residual: `predicted`, the rounded average of the ring's positions (exact
// integers); `ctx`, its residual context; `shift`, the precision it starts
// with: the coarsest of its ring vertices' (a finer residual would be below
// the prediction's own uncertainty), at least the record's `min_shift`. One
// function for the encoder and the decoder, so they cannot disagree. O(k).
struct InsertionPrediction {
  Vec3i predicted;
  ResidualContext ctx;
  int shift = 0;
};
void predict_insertion(const RefinementState& s, const std::vector<uint32_t>& ring, int min_shift,
                       InsertionPrediction& out);
// The residual of an inserted vertex at insertion, with its `shift` low
// bits left to plane records: per role the value sign * (|r| >> shift)
// through the model of scale bucket max(scale - shift, 0). `out` becomes the
// vertex's geometry (anchor = predicted). shift 0 codes exactly as format 1.
void encode_coarse_residual(RefinementModels& models, RangeEncoder& enc, const ResidualContext& ctx,
                            Vec3i actual, Vec3i predicted, int shift, VertexGeometry& out);
// Returns false when the decoded residual cannot belong to a grid position
// (shift 0: the position leaves the grid [0, max_coordinate]).
bool decode_coarse_residual(RefinementModels& models, RangeDecoder& dec, const ResidualContext& ctx,
                            Vec3i predicted, int shift, int32_t max_coordinate,
                            VertexGeometry& out);

// Inserts a vertex into a resolved patch and links it after the apex in the
// order list. Returns its id; appends written face slots to `touched`.
// The rank of a patch's start among rank_patch_starts' candidates.
void encode_start_rank(RefinementModels& m, RangeEncoder& enc, uint32_t k, uint32_t rank);
// Format 3: nothing when there is one candidate, else through the model of
// start_rank_context.
void encode_start_rank3(RefinementModels& m, RangeEncoder& enc, uint32_t context, size_t candidates,
                        uint32_t rank);
// rank_patch_starts with the candidates' scores in the same order.
void rank_patch_starts(const EditableMesh& mesh, uint32_t apex,
                       const std::vector<uint32_t>& star_ring, const std::vector<uint8_t>& used,
                       uint32_t k, std::vector<uint32_t>& out, std::vector<int64_t>& scores);
uint32_t decode_start_rank(RefinementModels& m, RangeDecoder& dec, uint32_t k);

uint32_t apply_patch(RefinementState& state, const ResolvedPatch& patch, uint32_t open,
                     Vec3i position, std::vector<uint32_t>* touched);
// The same for an embedded vertex: records its geometry and inserts it at
// reconstruct(geometry).
uint32_t apply_patch(RefinementState& state, const ResolvedPatch& patch, uint32_t open,
                     const VertexGeometry& geometry, std::vector<uint32_t>* touched);

struct RecordHeader {
  bool starts_layer = false;
  uint32_t walk_steps = 0;
  uint32_t insertions = 0;
  uint32_t min_shift = 0;  // format 2 only
};
void write_record_header(const RecordHeader& header, std::vector<uint8_t>& out, uint8_t format = 2);
void write_varint(uint32_t value, std::vector<uint8_t>& out);

struct AppliedRecord {
  std::vector<uint32_t> added_vertices;
  std::vector<uint32_t> touched_faces;
  std::vector<uint32_t> moved_vertices;  // plane records: positions that changed
};

// Decodes one refinement record and applies it to `state`. Every count,
// index and symbol is range-checked, so bad bytes never read or write out of
// bounds and never make a non-manifold mesh; on error `state` is left
// half-applied and must be discarded (IncrementalDecoder keeps its output
// mesh, updated only after a record succeeds, and stops there).
// O(record size + touched faces).
// `expected_vertices`/`expected_faces` are the index's counts after the
// record; a mismatch is an error (and rolls back) like any other.
// Plane records (flag kRecordPlane) are dispatched to apply_plane_record.
Status apply_refinement_record(RefinementState& state, std::span<const uint8_t> payload,
                               uint32_t expected_vertices, uint32_t expected_faces,
                               AppliedRecord& applied);

// A plane record: u8 flags (kRecordPlane), varint first vertex, varint
// vertex count, then one range-coded block with one plane step
// (embedded_geometry.h) for every vertex of [first, first + count) whose
// shift is not 0. The range must lie inside the mesh. The record's positions
// go to the mesh and `applied.moved_vertices`. O(count).
Status apply_plane_record(RefinementState& state, std::span<const uint8_t> payload,
                          AppliedRecord& applied);
// Encoder of the same; `residuals[v]` is vertex v's true residual against
// its anchor. Applies the step to `state` as the decoder will.
std::vector<uint8_t> write_plane_record(RefinementState& state, uint32_t first, uint32_t count,
                                        const std::vector<Vec3i>& residuals);

}  // namespace meshstream
