// Temporary entry points so meshstream-client links while the renderer is
// being written; replaced by window.cpp / snapshot.cpp.
#include "client/viewer/viewer.h"

namespace meshstream::client {

Status run_viewer(const ViewerOptions&, LatestFrameMailbox&, StreamControls&) {
  return make_error(ErrorCode::kUnsupported, "viewer: the window is not built yet");
}

Status render_snapshot(const Mesh&, const std::vector<FaceKind>*, const SnapshotOptions&,
                       const std::string&) {
  return make_error(ErrorCode::kUnsupported, "viewer: snapshots are not built yet");
}

}  // namespace meshstream::client
