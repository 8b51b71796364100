// Temporary: run_viewer until the window lands (window.cpp).
#include "client/viewer/viewer.h"

namespace meshstream::client {

Status run_viewer(const ViewerOptions&, LatestFrameMailbox&, StreamControls&) {
  return make_error(ErrorCode::kUnsupported, "viewer: the window is not built yet");
}

}  // namespace meshstream::client
