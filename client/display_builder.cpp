#include "client/display_builder.h"

#include <chrono>

namespace meshstream::client {

using Clock = std::chrono::steady_clock;

struct DisplayBuilder::State {
  AsaWorkspace workspace;
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
  if (!asa_enabled || options.levels == 0) return DisplayMesh{decoded_shared, nullptr};
  const auto start = Clock::now();
  AsaResult result;
  if (auto s = subdivide_into(*decoded_shared, options, state_->workspace, result); !s) {
    return tl::unexpected(s.error());
  }
  report.asa_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  DisplayMesh out;
  out.mesh = std::make_shared<const Mesh>(std::move(result.mesh));
  out.face_kind = std::make_shared<const std::vector<FaceKind>>(std::move(result.face_kind));
  return out;
}

}  // namespace meshstream::client
