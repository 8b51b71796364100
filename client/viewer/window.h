// The viewer window's loop, with a report of what it did (for tests and the
// client's summary). run_viewer (viewer.h) is this without the report.
#pragma once

#include <cstdint>

#include "client/viewer/viewer.h"

namespace meshstream::client {

struct ViewerReport {
  uint64_t frames_drawn = 0;
  uint64_t meshes_uploaded = 0;     // display meshes sent to the GPU
  uint64_t last_sequence_shown = 0; // DisplayFrame::sequence of the newest upload
  double max_upload_ms = 0;         // longest single upload (normals + buffers)
  double mean_frame_ms = 0;         // wall time per frame, including waits
};

// Opens the window, shows frames from `frames` as they arrive, steers the
// stream through `controls`, until the window is closed or
// options.exit_after_frames frames were drawn. kUnsupported when no display
// or no OpenGL 3.3 core context is available; kIo when exit_screenshot
// cannot be written. Runs on the calling thread (GLFW wants the main thread
// on some platforms).
Result<ViewerReport> run_viewer_with_report(const ViewerOptions& options,
                                            LatestFrameMailbox& frames, StreamControls& controls);

}  // namespace meshstream::client
