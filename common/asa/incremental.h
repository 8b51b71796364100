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
#pragma once

#include <cstdint>
#include <vector>

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
};

class IncrementalSubdivider {
 public:
  explicit IncrementalSubdivider(const AsaOptions& options,
                                 const IncrementalOptions& incremental = {});

  // Brings result() up to date with `input`. Vertices and faces are compared
  // with the previous input by index: vertex i is unchanged when its position
  // (and attributes) are bit-identical, face f when it has the same three
  // indices; new vertices and faces are appended (as the decoder does).
  // The result equals subdivide(input, options) face for face (same order and
  // bit-identical corner positions; vertex numbering may differ beyond the
  // input vertices, which keep their indices). Errors as subdivide(); after an
  // error the next update is a full one.
  // Cost: O(changed region) subdivision + O(output) copying. With a camera
  // (options.view), even a first or full update subdivides only the region
  // of faces whose edges may matter on screen (one pass over the faces finds
  // them), when that region is small.
  Status update(const Mesh& input);

  const AsaResult& result() const { return result_; }
  const IncrementalStats& last_update() const { return stats_; }
  // Forgets the previous input: the next update subdivides everything.
  void reset() { has_previous_ = false; }

  // A new camera (or tolerance) for view-dependent ASA, used from the next
  // update on. That update redoes, besides what the input changed, the input
  // faces whose refinement the new view or the old one may ask for: a face
  // whose every possible edge (its own and its descendants', which stay
  // inside a sphere around it) is below the tolerance or outside the frustum
  // for both views keeps its patch, unless the closure around it changed,
  // which the seam check finds. Cost: O(F) sphere tests.
  void set_view(const AsaView& view);
  const AsaOptions& options() const { return options_; }

 private:
  Status full_update(const Mesh& input);
  bool view_region_update(const Mesh& input);
  void remember(const Mesh& input);
  // The phases of update(), in order (see incremental.cpp).
  uint32_t mark_changed_vertices(const Mesh& input);
  uint32_t mark_view_changes(const Mesh& input);
  void index_vertex_faces(const Mesh& input);
  uint32_t grow_region(const Mesh& input, uint32_t attempt);
  void extract_region(const Mesh& input);
  bool seam_matches();
  void splice(const Mesh& input);

  AsaOptions options_;
  IncrementalOptions incremental_;
  AsaWorkspace workspace_;
  bool has_previous_ = false;
  bool view_changed_ = false;          // set_view since the last update
  AsaView previous_view_;              // the view the result was made for
  Mesh previous_;                      // the previous input
  std::vector<uint32_t> patch_start_;  // per previous input face, into result_ faces (+1 sentinel)
  AsaResult result_;
  IncrementalStats stats_;
  // Scratch reused between updates.
  AsaResult region_result_, next_;
  Mesh region_;
  std::vector<uint32_t> vertex_faces_offset_, vertex_faces_, local_vertex_, global_vertex_,
      region_faces_;
  std::vector<uint32_t> local_face_, region_patch_start_, seam_map_, new_id_prev_, new_id_region_;
  std::vector<uint8_t> changed_vertex_, dirty_face_, in_region_, vertex_mark_;
  std::vector<uint32_t> frontier_, next_frontier_, seam_faces_;
};

}  // namespace meshstream
