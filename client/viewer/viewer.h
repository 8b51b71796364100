// The streaming viewer: a live window (GLFW, OpenGL 3.3 core, Dear ImGui)
// that shows the newest display mesh, and the same renderer off-screen for
// snapshots without any display.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "client/display_frame.h"
#include "common/base/result.h"

namespace meshstream::client {

struct ViewerOptions {
  int width = 1280;
  int height = 800;
  std::string title = "meshstream";
  // Close the window after this many frames (0: run until the user closes
  // it); for tests under Xvfb.
  uint64_t exit_after_frames = 0;
  // Close the window once a frame with at least this many decoded records
  // has been drawn (0: off); for tests that must close mid-stream whatever
  // the display's frame rate.
  uint32_t exit_after_records = 0;
  // When not empty: the last drawn frame (model only, no panel) is written
  // to this PNG as the window closes; for tests and scripted captures.
  std::string exit_screenshot;
  bool exit_screenshot_with_panel = false;  // include the ImGui panel in it
  // Colouring at start: 0 shaded, 1 what ASA did, 2 distance to the final mesh.
  int initial_coloring = 0;
  bool initial_wireframe = false;
  std::string screenshot_dir = ".";  // where the screenshot button writes
  // Scripted orbit: the camera turns this many degrees per frame once the
  // model is framed (0: off); for captures and benchmarks under Xvfb.
  float orbit_degrees_per_frame = 0;
};

// Opens the window and runs the render loop on the calling thread until the
// user closes it (or exit_after_frames). Uploads happen here; decode and ASA
// stay on the pipeline's threads. kUnsupported when no display can be opened.
// For scripted captures (docs/images/make_snapshot_strip.sh) the environment
// may fill options the caller left at their defaults:
// MESHSTREAM_VIEWER_CAPTURE=FILE.png (exit screenshot with the panel),
// MESHSTREAM_VIEWER_COLORING=shaded|kinds|distance, MESHSTREAM_VIEWER_WIREFRAME=1,
// MESHSTREAM_VIEWER_ORBIT=DEGREES (turned per frame).
Status run_viewer(const ViewerOptions& options, LatestFrameMailbox& frames,
                  StreamControls& controls);

struct SnapshotOptions {
  int width = 1024;
  int height = 768;
  enum class Coloring { kShaded, kAsaKinds } coloring = Coloring::kShaded;
  bool wireframe = false;
  // Shading keeps edges bending more than this sharp (the user's --crease;
  // 0: kDefaultShadingCreaseDegrees, 60).
  float crease_degrees = 0.0f;
  // The camera to render with (the one the display was refined for); unset:
  // the whole model framed.
  std::optional<AsaCamera> camera;
  // When set, the framing (without a camera) and the near and far planes
  // come from this mesh (the whole display when `mesh` is its cull).
  const Mesh* frame_on = nullptr;
};

// Renders `mesh` off-screen (OSMesa) with the viewer's renderer, framing the
// whole model (or from options.camera), and writes a PNG. `face_kind` may be null.
Status render_snapshot(const Mesh& mesh, const std::vector<FaceKind>* face_kind,
                       const SnapshotOptions& options, const std::string& png_path);

}  // namespace meshstream::client
