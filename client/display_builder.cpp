#include "client/display_builder.h"

#include <algorithm>
#include <atomic>
#include <chrono>

#include "common/asa/corner_attributes.h"
#include "common/asa/display_budget.h"
#include "common/asa/incremental.h"

namespace meshstream::client {

using Clock = std::chrono::steady_clock;

namespace {
double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// Everything but the view (a camera move is handled incrementally).
bool same_options(const AsaOptions& a, const AsaOptions& b) {
  return a.view.enabled == b.view.enabled && a.levels == b.levels && a.flatness == b.flatness &&
         a.uniform == b.uniform && a.rule == b.rule && a.tension == b.tension &&
         a.crease_degrees == b.crease_degrees;
}
}  // namespace

struct DisplayBuilder::State {
  AsaWorkspace workspace;  // full path
  // Incremental path (common/asa/incremental.h): keeps the previous input
  // and result, recomputes the region around what changed, and falls back to
  // a full run itself when more than `dirty_fraction` of the mesh changed.
  std::unique_ptr<IncrementalSubdivider> incremental;
  AsaOptions incremental_options;
  float dirty_fraction = 0.25f;
  double full_ms_per_face = 0;  // measured on the last full run
  std::vector<uint8_t> seen;    // scratch: changed faces counted once
  // The incremental path's display meshes: copies of its result, handed to
  // frames. One no frame holds any more is brought up to date again: only
  // what the updates since its version changed is copied
  // (IncrementalSubdivider::copy_result_into), into the memory it had.
  struct PooledDisplay {
    std::shared_ptr<Mesh> mesh = std::make_shared<Mesh>();
    std::shared_ptr<std::vector<FaceKind>> kinds = std::make_shared<std::vector<FaceKind>>();
    uint64_t version = 0;  // of the incremental result it copies
  };
  std::vector<PooledDisplay> display_pool;
};

DisplayBuilder::DisplayBuilder() : state_(std::make_unique<State>()) {}
DisplayBuilder::~DisplayBuilder() = default;
DisplayBuilder::DisplayBuilder(DisplayBuilder&&) noexcept = default;
DisplayBuilder& DisplayBuilder::operator=(DisplayBuilder&&) noexcept = default;

namespace {

// What ASA's output lacks of the decoded mesh's surface: its materials and
// textures (mesh-wide, unchanged by subdivision; per-corner attributes and
// face materials ASA carries itself).
std::shared_ptr<const Mesh> with_surface(Mesh display, const Mesh& decoded) {
  display.materials = decoded.materials;
  display.textures = decoded.textures;
  return std::make_shared<const Mesh>(std::move(display));
}

// The entry of `pool` no one else holds with the newest copy (the least to
// bring up to date); a new one when all are held (the pool keeps at most
// three).
template <class Entry>
Entry free_entry(std::vector<Entry>& pool) {
  Entry* best = nullptr;
  for (auto& entry : pool) {
    if (entry.mesh.use_count() != 1 || entry.kinds.use_count() != 1) continue;
    if (!best || entry.version > best->version) best = &entry;
  }
  if (best) {
    // The last holder's release (a frame on another thread) comes before
    // our writes (as in frame_mesh_pool.cpp).
    std::atomic_thread_fence(std::memory_order_acquire);
    return *best;
  }
  Entry entry;
  if (pool.size() < 3) pool.push_back(entry);
  return entry;
}

}  // namespace

Result<DisplayMesh> DisplayBuilder::build(const std::shared_ptr<const Mesh>& decoded_shared,
                                          const MeshChanges& changes, bool asa_enabled,
                                          const AsaOptions& options, bool options_changed,
                                          BuildReport& report) {
  // The incremental subdivider finds the changes itself, by index; `changes`
  // only steers the auto path's choice below.
  report = {};
  State& s = *state_;
  if (!asa_enabled || options.levels == 0) {
    s.incremental.reset();
    return DisplayMesh{decoded_shared, nullptr};
  }
  const Mesh& mesh = *decoded_shared;
  const uint32_t F = mesh.face_count();
  const auto start = Clock::now();

  // Auto: an update that rewrote a large part of the mesh (typically many
  // coalesced records) goes straight to a plain full run; the incremental
  // subdivider would only find that out after diffing the whole mesh, and
  // its result would still have to be copied.
  bool plain_full = path_ == AsaPath::kFull;
  if (path_ == AsaPath::kAuto && !changes.full && !options_changed && F > 0) {
    // `seen` stays all zero between updates (the marks are undone below),
    // so counting costs the changes, not a clearing pass over every face.
    if (s.seen.size() < F) s.seen.resize(F, 0);
    uint32_t unique = 0;
    for (uint32_t f : changes.faces) {
      if (f < F && !s.seen[f]) {
        s.seen[f] = 1;
        ++unique;
      }
    }
    for (uint32_t f : changes.faces)
      if (f < F) s.seen[f] = 0;
    if (!changes.moved.empty() && mesh.vertex_count() > 0) {
      // Moved vertices (plane records) change the shape of every face
      // around them: about 3F/V faces each (the mean valence), estimated
      // from the count rather than found by an O(F) scan of the faces on
      // every plane record. Plane records cover vertex index ranges, which
      // are spread over the whole surface, so this usually picks the full
      // run (measured on the demo model: the region would be 27-63 % of the
      // faces and no faster).
      const double per_vertex = 3.0 * double(F) / double(mesh.vertex_count());
      unique = static_cast<uint32_t>(
          std::min<double>(double(F), double(unique) + per_vertex * double(changes.moved.size())));
    }
    // The dirty region is the changed faces widened by a few rings: several
    // times larger than the changed faces themselves.
    plain_full = 4.0 * double(unique) > double(s.dirty_fraction) * double(F);
  } else if (path_ == AsaPath::kAuto && changes.full) {
    plain_full = true;
  }
  // Per-corner attributes and face materials ride through the full
  // subdivision only (corner_attributes.h; the incremental subdivider's
  // region merge does not carry them yet).
  const bool corner_data = asa::has_corner_data(mesh);
  if (corner_data) plain_full = true;
  if (plain_full && !corner_data && options.view.enabled && path_ != AsaPath::kFull) {
    // A camera bounds the work: the incremental subdivider redoes the
    // region the change and the screen ask for, and where that is most of
    // the mesh its own full update subdivides only the region the screen
    // may refine (incremental.h).
    if (s.incremental && changes.full) s.incremental->reset();
    plain_full = false;
  }
  report.pixel_tolerance = options.view.enabled ? options.view.pixel_tolerance : 0;
  report.levels_used = options.levels;
  auto budgeted_full_run = [&]() -> Result<DisplayMesh> {
    s.incremental.reset();
    AsaResult result;
    BudgetOutcome outcome;
    if (auto st = subdivide_within_budget(mesh, options, max_faces_, s.workspace, result, outcome);
        !st)
      return tl::unexpected(st.error());
    report.pixel_tolerance = outcome.pixel_tolerance;
    report.budget_limited = outcome.limited;
    report.levels_used = outcome.levels;
    report.incremental = false;
    report.asa_ms = ms_since(start);
    DisplayMesh out;
    out.mesh = with_surface(std::move(result.mesh), mesh);
    out.face_kind = std::make_shared<const std::vector<FaceKind>>(std::move(result.face_kind));
    return out;
  };
  if (plain_full) {
    s.incremental.reset();
    AsaResult result;
    if (auto st = subdivide_into(mesh, options, s.workspace, result); !st)
      return tl::unexpected(st.error());
    if (max_faces_ > 0 && result.mesh.face_count() > max_faces_) return budgeted_full_run();
    report.asa_ms = ms_since(start);
    if (F > 0) s.full_ms_per_face = report.asa_ms / double(F);
    DisplayMesh out;
    out.mesh = with_surface(std::move(result.mesh), mesh);
    out.face_kind = std::make_shared<const std::vector<FaceKind>>(std::move(result.face_kind));
    return out;
  }

  if (!s.incremental || options_changed || !same_options(options, s.incremental_options)) {
    IncrementalOptions io;
    // Forced incremental: region updates unless the subdivider cannot prove
    // the seam; auto: its default threshold, lowered when measured slower.
    io.max_dirty_fraction = path_ == AsaPath::kIncremental ? 1.0f : s.dirty_fraction;
    s.incremental = std::make_unique<IncrementalSubdivider>(options, io);
    s.incremental_options = options;
  } else {
    s.incremental->set_view(options.view);  // nothing when it is the same
  }
  // The decoder's report of what changed spares the subdivider a
  // comparison of the whole mesh (valid only against the previous call's
  // input, which the subdivider saw unless it was just made or reset).
  InputChanges reported;
  reported.vertices = changes.vertices;
  reported.moved = changes.moved;
  reported.faces = changes.faces;
  const bool use_report = changes_exact_ && !changes.full && !options_changed;
  if (auto st = s.incremental->update(mesh, use_report ? &reported : nullptr); !st)
    return tl::unexpected(st.error());
  const IncrementalStats& stats = s.incremental->last_update();
  const AsaResult& result = s.incremental->result();
  if (max_faces_ > 0 && result.mesh.face_count() > max_faces_) return budgeted_full_run();
  State::PooledDisplay entry = free_entry(s.display_pool);
  s.incremental->copy_result_into(*entry.mesh, *entry.kinds, entry.version);
  for (auto& pooled : s.display_pool)
    if (pooled.mesh == entry.mesh) pooled.version = entry.version;
  std::shared_ptr<Mesh> display = std::move(entry.mesh);
  display->materials = mesh.materials;
  display->textures = mesh.textures;
  std::shared_ptr<std::vector<FaceKind>> kinds = std::move(entry.kinds);
  report.asa_ms = ms_since(start);
  report.incremental = !stats.full;
  report.region_faces = stats.region_faces;
  report.unused_vertices = s.incremental->unused_vertices();
  if (stats.full) {
    if (F > 0) s.full_ms_per_face = report.asa_ms / double(F);
  } else if (path_ == AsaPath::kAuto && s.full_ms_per_face > 0 && F > 0) {
    // Keep the faster path: when a region update cost more than a full run
    // would have, make regions of this size go the full way from now on.
    const double full_estimate = s.full_ms_per_face * double(F);
    const float dirty = static_cast<float>(double(stats.dirty_faces) / double(F));
    if (report.asa_ms > full_estimate && dirty < s.dirty_fraction) {
      s.dirty_fraction = std::max(0.01f, dirty * 0.8f);
      s.incremental.reset();  // re-created with the new threshold next time
    }
  }
  return DisplayMesh{std::move(display), std::move(kinds)};
}

}  // namespace meshstream::client
