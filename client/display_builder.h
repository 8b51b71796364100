// Turns the decoded mesh into the display mesh after each update: ASA
// (common/asa/subdivide.h) either on the whole mesh, or incrementally on
// the region the update changed (common/asa/incremental.h), keeping
// whichever path has been faster for updates of that size. Both paths give
// the same triangles with the same positions; the incremental path's are in
// another order and its mesh has unused vertex slots (IncrementalSubdivider::
// result()): each update copies into the display only what it changed.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "client/decoded_stream.h"
#include "common/asa/subdivide.h"
#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream::client {

enum class AsaPath { kAuto, kFull, kIncremental };

struct BuildReport {
  double asa_ms = 0;
  bool incremental = false;   // which path produced this display mesh
  uint32_t region_faces = 0;  // decoded faces recomputed (incremental path)
  // View-dependent ASA: the tolerance used (0 without a camera); raised
  // above the requested one when the display budget was reached.
  float pixel_tolerance = 0;
  bool budget_limited = false;   // the budget cut this update (tolerance or levels)
  int levels_used = 0;           // ASA levels the kept run allowed
  uint32_t unused_vertices = 0;  // display vertex slots no face uses (incremental path)
};

struct DisplayMesh {
  std::shared_ptr<const Mesh> mesh;
  std::shared_ptr<const std::vector<FaceKind>> face_kind;  // null without ASA
};

class DisplayBuilder {
 public:
  DisplayBuilder();
  ~DisplayBuilder();
  DisplayBuilder(DisplayBuilder&&) noexcept;
  DisplayBuilder& operator=(DisplayBuilder&&) noexcept;

  void set_path(AsaPath path) { path_ = path; }
  // The display budget (--max-display-faces; 0 = none), see display_budget.h.
  void set_max_faces(uint64_t max_faces) { max_faces_ = max_faces; }
  // The `changes` given to build() are exact (the pipeline's, from the
  // decoder's record deltas): the incremental path then takes them instead
  // of comparing the whole mesh with the previous one. Off by default, so a
  // caller that passes no or partial changes still gets a correct display.
  void set_changes_exact(bool exact) { changes_exact_ = exact; }

  // The display mesh of `decoded`, which differs from the previous call's
  // input by `changes` (ignored when `options_changed` or on the first
  // call). A new camera or tolerance in options.view alone is not an options
  // change: the incremental path redoes only what the views may refine. `decoded_shared` is
  // returned as is when ASA is off. Errors: those of subdivide() (a mesh ASA cannot work on).
  Result<DisplayMesh> build(const std::shared_ptr<const Mesh>& decoded_shared,
                            const MeshChanges& changes, bool asa_enabled, const AsaOptions& options,
                            bool options_changed, BuildReport& report);

 private:
  struct State;
  std::unique_ptr<State> state_;
  AsaPath path_ = AsaPath::kAuto;
  uint64_t max_faces_ = 0;
  bool changes_exact_ = false;
};

}  // namespace meshstream::client
