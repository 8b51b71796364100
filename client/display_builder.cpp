#include "client/display_builder.h"

#include <algorithm>
#include <chrono>

#include "client/incremental_asa.h"

namespace meshstream::client {

using Clock = std::chrono::steady_clock;

namespace {
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }
}  // namespace

struct DisplayBuilder::State {
  AsaWorkspace workspace;
  AsaWorkspace region_workspace;
  IncrementalAsa incremental;
  // Auto path: the region size (as a fraction of the mesh's faces) up to
  // which the incremental path is tried; adapted from measurements.
  double region_fraction = 0.5;
  double full_ms_per_face = 0;  // last full run (subdivide + adopt), per decoded face
};

DisplayBuilder::DisplayBuilder() : state_(std::make_unique<State>()) {}
DisplayBuilder::~DisplayBuilder() = default;
DisplayBuilder::DisplayBuilder(DisplayBuilder&&) noexcept = default;
DisplayBuilder& DisplayBuilder::operator=(DisplayBuilder&&) noexcept = default;

Result<DisplayMesh> DisplayBuilder::build(const std::shared_ptr<const Mesh>& decoded_shared,
                                          const MeshChanges& changes, bool asa_enabled,
                                          const AsaOptions& options, bool options_changed,
                                          BuildReport& report) {
  report = {};
  State& s = *state_;
  if (!asa_enabled || options.levels == 0) {
    s.incremental.reset();
    return DisplayMesh{decoded_shared, nullptr};
  }
  const Mesh& mesh = *decoded_shared;
  const uint32_t F = mesh.face_count();
  const bool can_increment = path_ != AsaPath::kFull && IncrementalAsa::supports(options);
  const auto start = Clock::now();

  if (can_increment && s.incremental.ready() && !options_changed && !changes.full) {
    const uint32_t limit = path_ == AsaPath::kIncremental
                               ? UINT32_MAX - 1
                               : static_cast<uint32_t>(s.region_fraction * double(F));
    const uint32_t region = s.incremental.plan(mesh, changes, limit);
    if (region != UINT32_MAX && s.incremental.update(mesh, options, s.region_workspace)) {
      auto display = std::make_shared<Mesh>();
      auto kinds = std::make_shared<std::vector<FaceKind>>();
      s.incremental.assemble(mesh, *display, *kinds);
      report.asa_ms = ms_since(start);
      report.incremental = true;
      report.region_faces = s.incremental.last_region_faces;
      // Adapt: if this cost more than a full run would have, try smaller regions.
      if (s.full_ms_per_face > 0) {
        const double full_estimate = s.full_ms_per_face * double(F);
        const double used = double(s.incremental.last_submesh_faces) / std::max(1.0, double(F));
        if (report.asa_ms > full_estimate) {
          s.region_fraction = std::max(0.02, std::min(s.region_fraction, used) * 0.8);
        } else {
          s.region_fraction = std::min(0.9, s.region_fraction * 1.05);
        }
      }
      return DisplayMesh{std::move(display), std::move(kinds)};
    }
    // Too large, or not mergeable: recompute everything below.
  }

  AsaResult result;
  if (auto st = subdivide_into(mesh, options, s.workspace, result); !st) return tl::unexpected(st.error());
  if (can_increment) {
    if (!s.incremental.adopt(mesh, options, result)) s.incremental.reset();
  } else {
    s.incremental.reset();
  }
  report.asa_ms = ms_since(start);
  if (F > 0) s.full_ms_per_face = report.asa_ms / double(F);
  DisplayMesh out;
  out.mesh = std::make_shared<const Mesh>(std::move(result.mesh));
  out.face_kind = std::make_shared<const std::vector<FaceKind>>(std::move(result.face_kind));
  return out;
}

}  // namespace meshstream::client
