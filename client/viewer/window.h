// The viewer window's loop, with a report of what it did (for tests and the
// client's summary). run_viewer (viewer.h) is this without the report.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "client/viewer/viewer.h"
#include "common/asa/subdivide.h"

namespace meshstream::client {

// What a person can ask with keys or the panel; tests script these by frame.
enum class ViewerCommand {
  kFrameModel,       // F
  kToggleWireframe,  // W
  kColorShaded,      // 1
  kColorAsaKinds,    // 2
  kColorDistance,    // 3
  kTogglePause,      // Space (StreamControls::pause / resume)
  kScreenshot,       // S (PNG of the model in ViewerOptions::screenshot_dir)
  kClose,            // Escape
  kSetAsa,           // the panel's ASA controls (StreamControls::set_asa)
};

struct ScriptedCommand {
  uint64_t at_frame = 0;  // applied before drawing this frame (0-based)
  ViewerCommand command = ViewerCommand::kFrameModel;
  bool asa_enabled = true;  // kSetAsa only
  AsaOptions asa;           // kSetAsa only
};

struct ViewerReport {
  uint64_t frames_drawn = 0;
  uint64_t meshes_uploaded = 0;      // display meshes sent to the GPU
  uint64_t last_sequence_shown = 0;  // DisplayFrame::sequence of the newest upload
  double max_upload_ms = 0;          // longest single upload (normals + buffers)
  double mean_frame_ms = 0;          // wall time per frame, including waits
  uint64_t distance_uploads = 0;     // per-vertex distances to the final mesh shown
  uint64_t rejected_meshes = 0;      // frames whose mesh failed validate_arrays
  uint64_t cameras_sent = 0;         // camera moves handed to view-dependent ASA
  // The camera left the shown cull's region: the whole display was uploaded.
  uint64_t whole_display_uploads = 0;
  // Frames drawn once a mesh had been shown but with none on the GPU (the
  // renderer keeps the last upload, so a re-run of ASA never blanks the
  // window), and frames drawn before the first mesh arrived.
  uint64_t frames_without_mesh = 0;
  uint64_t frames_before_first_mesh = 0;
  double max_frame_ms = 0;  // longest frame's own work (input, upload, draw, swap), no waiting
  std::vector<std::string> screenshots;  // PNGs written by kScreenshot
  int final_coloring = 0;                // ColorMode at exit
  bool final_wireframe = false;
};

// Opens the window, shows frames from `frames` as they arrive, steers the
// stream through `controls`, until the window is closed, `frames` is
// closed (the client's Ctrl-C) or options.exit_after_frames frames were
// drawn. kUnsupported when no display
// or no OpenGL 3.3 core context is available; kIo when exit_screenshot
// cannot be written. Runs on the calling thread (GLFW wants the main thread
// on some platforms).
// `script` injects commands as if typed (for tests; keys and the panel use
// the same path).
Result<ViewerReport> run_viewer_with_report(const ViewerOptions& options,
                                            LatestFrameMailbox& frames, StreamControls& controls,
                                            const std::vector<ScriptedCommand>& script = {});

}  // namespace meshstream::client
