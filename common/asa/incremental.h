// Incremental ASA for a mesh that changes a little between calls (the client
// subdivides after every decoded record): only the input faces near what
// changed are subdivided again; every other input face's output patch is
// copied from the previous result.
//
// Why it is exact: the Butterfly stencils reach a bounded number of rings, and
// every input face's output is a contiguous patch (AsaResult::source_face).
// A region of the changed faces plus context rings is subdivided on its own;
// the patches of the clean faces bordering the changed ones are recomputed in
// that run too and must come out bit-identical to their previous versions
// (positions and connectivity); that proves the seam matches and gives the
// identity of every seam vertex. If they differ (ASA closure reached further
// than the region), the region grows; after a few tries, or when most of the
// mesh changed, the whole mesh is subdivided again.
//
// The result is kept in place: an update rewrites only the output faces of
// the input faces it redid and the output vertices it made or moved (O(change),
// no copy of the whole output), so its faces are not in input-face order and
// it may hold unused vertex slots (see result()).
#pragma once

#include <algorithm>
#include <cstdint>
#include <deque>
#include <span>
#include <vector>

#include "common/asa/corner_table.h"
#include "common/asa/level_mesh.h"
#include "common/asa/subdivide.h"

namespace meshstream {

struct IncrementalOptions {
  uint32_t dirty_rings = 3;          // faces within this many rings of a change are redone
  uint32_t context_rings = 4;        // extra rings subdivided around them as context
  float max_dirty_fraction = 0.25f;  // redo everything when more of the mesh changed
  uint32_t max_attempts = 3;         // region growths before falling back to a full run
};

struct IncrementalStats {
  bool full = false;              // the whole mesh was subdivided
  uint32_t changed_vertices = 0;  // input vertices moved, added or re-connected
  uint32_t dirty_faces = 0;       // input faces whose patches were recomputed
  uint32_t region_faces = 0;      // faces of the submesh that was subdivided
  uint32_t attempts = 0;          // subdivisions of a region this update
  uint32_t view_faces = 0;        // input faces redone because the view changed
  // The result was made anew (a full or view-region run, or its vertices
  // renumbered): a copy of it is copied whole once.
  bool rebuilt = false;
};

// What changed in the input since the previous update, as the decoder
// reports it (RecordDelta): with it an update costs the change, without it
// the subdivider compares the whole input with the previous one. Vertices
// and faces appended since the previous update count as changed whether
// listed or not; lists may repeat. A vertex not listed must keep its
// position and attributes, a face not listed its corners.
struct InputChanges {
  std::span<const uint32_t> vertices;  // added
  std::span<const uint32_t> moved;     // existing ones moved or given new attributes
  std::span<const uint32_t> faces;     // created or rewritten
};

class IncrementalSubdivider {
 public:
  explicit IncrementalSubdivider(const AsaOptions& options,
                                 const IncrementalOptions& incremental = {});

  // Brings result() up to date with `input`. Vertices and faces are compared
  // with the previous input by index: vertex i is unchanged when its position
  // (and attributes) are bit-identical, face f when it has the same three
  // indices; new vertices and faces are appended (as the decoder does).
  // The result equals subdivide(input, options) as a set of faces: the same
  // triangles (bit-identical corner positions, same corner order) with the
  // same face kinds, in another order; canonical() gives them face for face
  // in subdivide()'s order. Errors as subdivide(); after an error the next
  // update is a full one.
  // Cost: O(changed region) subdivision and splice (no O(output) pass,
  // except vertex normals when the input has normals); the level-0
  // adjacency (asa::LiveCornerTable) and face normals are kept up to date
  // with what changed, not rebuilt. With `changes` finding what changed
  // costs the change too; without, one comparison pass over the input.
  // With a camera (options.view), even a first or full update subdivides
  // only the region around the faces ASA targets on screen (flatness and
  // view, one pass over the faces finds them), unless that is most of the
  // mesh.
  Status update(const Mesh& input, const InputChanges* changes = nullptr);

  // The output, in place: input vertex i is output vertex i; output vertices
  // [input vertex count, input_slots()) and the free slots beyond it are used
  // by no face (their positions are old or another vertex's, so a bounding
  // box of the positions stays on the surface); source_face names each
  // face's input face (patches are not contiguous). The unused vertices are
  // at most 1/8 of the output's plus headroom for the input's growth; past
  // that (or when the input outgrows its slots) the vertices are renumbered
  // (O(output), that update is a whole change).
  const AsaResult& result() const { return result_; }
  uint32_t input_slots() const { return input_slots_; }
  // Output vertex slots no face uses: result().mesh.vertex_count() minus
  // this is subdivide()'s vertex count. O(1).
  uint32_t unused_vertices() const {
    const uint32_t inputs = std::min(previous_.vertex_count(), input_slots_);
    return input_slots_ - inputs + static_cast<uint32_t>(free_vertices_.size());
  }
  // The result as subdivide() gives it: faces in input-face order (each
  // patch in its order), input vertices first, then the others as first
  // used. O(output); for tests and tools.
  AsaResult canonical() const;

  // Each update that may change result() gives it a new version (unique
  // across instances). copy_result_into brings a copy of result() made at
  // version `version` up to date by copying only what the updates since then
  // changed (O(change)) when they are still logged, else copies all of it;
  // then sets `version` (0: a copy of nothing yet). After it, `mesh` and
  // `kinds` equal result().mesh (its arrays: positions, triangles, colors,
  // texcoords, normals) and result().face_kind element for element. True
  // when only the changes were copied.
  uint64_t version() const { return version_; }
  bool copy_result_into(Mesh& mesh, std::vector<FaceKind>& kinds, uint64_t& version) const;
  const IncrementalStats& last_update() const { return stats_; }
  // Forgets the previous input: the next update subdivides everything.
  void reset() { has_previous_ = false; }

  // A new camera (or tolerance) for view-dependent ASA, used from the next
  // update on. That update redoes, besides what the input changed, the input
  // faces whose refinement the new view or the old one may ask for: a face
  // whose level-0 ASA target flag (flatness and view) is the same for both
  // views keeps its patch; with more than one level, a face that was or
  // becomes refined is redone too unless it is wholly below the tolerance
  // or outside the frustum for both views (its descendants stay inside a
  // sphere around it). Changes of the closure beyond the faces redone are
  // found by the seam check. Cost: two O(F) target passes (a dot product
  // per edge, the view test only for bent edges) plus the region.
  void set_view(const AsaView& view);
  const AsaOptions& options() const { return options_; }

 private:
  Status full_update(const Mesh& input, bool level0_current = false);
  bool ensure_level0(const Mesh& input);
  bool view_region_update(const Mesh& input);
  void remember(const Mesh& input);
  // The phases of update(), in order (see incremental.cpp).
  Status collect_changes_by_diff(const Mesh& input);
  Status collect_reported_changes(const Mesh& input, const InputChanges& changes);
  void mark_vertex(uint32_t v);
  void clear_vertex_marks();
  void bring_previous_up_to_date(const Mesh& input);
  void refresh_face_normals(const Mesh& input);
  bool rebuild_level0(const Mesh& input);
  asa::LevelView level0(const Mesh& input);
  uint32_t mark_view_changes(const Mesh& input);
  uint32_t mark_view_changes_of_bent_faces(const Mesh& input);
  void rebuild_bent(const Mesh& input);
  void refresh_bent(const Mesh& input);
  uint8_t bent_bits(uint32_t f) const;
  void set_bent(uint32_t f, uint8_t bits);
  void refresh_bent_block(const Mesh& input, uint32_t block);
  void next_generation(uint32_t faces, uint32_t vertices);
  bool is_dirty(uint32_t f) const { return dirty_stamp_[f] == generation_; }
  uint32_t grow_region(const Mesh& input, uint32_t attempt);
  void close_region_fans(const Mesh& input);
  void extract_region(const Mesh& input);
  bool seam_matches();
  void splice(const Mesh& input);
  // In-place layout (see result()).
  void adopt_canonical(uint32_t input_vertices, uint32_t input_faces);
  void relayout(uint32_t input_slots);
  uint32_t headroom_for(uint32_t input_vertices) const;
  uint32_t new_vertex_slot();
  void release_vertex(uint32_t v);
  void move_face(uint32_t from, uint32_t to);
  struct Change;
  void open_change();
  Change& current_change() { return log_.back(); }

  AsaOptions options_;
  IncrementalOptions incremental_;
  AsaWorkspace workspace_;
  bool has_previous_ = false;
  bool view_changed_ = false;  // set_view since the last update
  AsaView previous_view_;      // the view the result was made for
  Mesh previous_;              // the previous input
  AsaResult result_;
  // Per previous input face: its patch as a list of result_ faces, in the
  // patch's order (first face, then next_in_patch_ per face; kNone ends it).
  std::vector<uint32_t> patch_first_, patch_size_, next_in_patch_;
  std::vector<uint32_t> vertex_refs_;    // per output vertex: corners using it
  std::vector<uint32_t> free_vertices_;  // unused output vertices >= input_slots_
  uint32_t input_slots_ = 0;
  // What each recent update changed in result_ (by index), for copies.
  struct Change {
    uint64_t version = 0;
    bool whole = false;
    std::vector<uint32_t> faces, vertices;
  };

 public:
  static constexpr size_t kLoggedChanges = 8;  // a copy this many updates behind is patched

 private:
  std::deque<Change> log_;
  uint64_t version_ = 0;
  IncrementalStats stats_;
  // Level 0 of the previous input, kept up to date with the changes.
  bool level0_valid_ = false;
  asa::LiveCornerTable table_;
  std::vector<Vec3f> face_normal_;
  std::vector<uint8_t> feature_, target_before_, target_after_;
  // With a camera: the part of the level-0 targets no camera changes, kept
  // up to date with the records: per face a bit per corner whose edge is
  // bent (interior, not a feature, N1.N2 <= t), so that a camera move asks
  // the view only about bent edges. feature_ is kept up to date alongside.
  bool bent_valid_ = false;
  std::vector<uint8_t> bent_mask_;
  // The bent edges by blocks of kBentBlock consecutive faces: a sphere
  // holding their midpoints and their longest length, so that a camera
  // move skips a block whose edges no view can ask for (ViewTest::
  // may_matter) without looking at its faces. A block is recomputed when
  // one of its faces' bits are set again (stale).
  static constexpr uint32_t kBentBlock = 64;
  struct BentBlock {
    uint32_t bent_faces = 0;
    Vec3f centre{};
    float radius = 0, longest = 0;
    bool stale = false;  // listed in stale_blocks_
  };
  std::vector<BentBlock> bent_blocks_;
  std::vector<uint32_t> stale_blocks_;
  std::vector<uint32_t> refreshed_faces_;  // faces whose normals this update recomputed
  // What changed this update: vertex marks (all zero between updates) and
  // their list; changed faces with their previous corners.
  std::vector<uint8_t> changed_vertex_;
  std::vector<uint32_t> changed_list_, changed_faces_;
  std::vector<Triangle> old_corners_;
  // Per face / vertex stamps: equal to generation_ means set this pass, so
  // nothing is cleared per update.
  uint32_t generation_ = 0;
  std::vector<uint32_t> dirty_stamp_, region_stamp_, face_seen_, vertex_seen_, local_stamp_;
  // Scratch reused between updates.
  AsaResult region_result_;
  Mesh region_;
  std::vector<uint32_t> local_vertex_, global_vertex_, region_faces_;
  std::vector<uint32_t> local_face_, region_patch_start_, seam_map_, new_id_, new_id_region_;
  std::vector<uint32_t> free_faces_, patch_tail_;
  std::vector<uint32_t> frontier_, next_frontier_, seam_faces_;
};

}  // namespace meshstream
