// The Dear ImGui panel of the viewer window: stream statistics, display
// settings and the controls that steer the stream (ASA, pause).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "client/display_frame.h"
#include "client/viewer/mesh_renderer.h"

namespace meshstream::client {

// Everything the panel shows or edits that outlives a frame.
struct PanelState {
  // display
  ColorMode coloring = ColorMode::kShaded;
  // Shaded mode on a mesh with colours or a texture: lit base colour x
  // texture, the base colour alone, or the texture alone.
  SurfaceMode surface = SurfaceMode::kLit;
  bool mesh_has_surface = false;  // the shown mesh has colours or a texture
  bool wireframe = false;
  bool distance_auto = true;  // ramp maximum = 98th percentile of the distances
  float distance_p98 = 0;
  float distance_max_percent = 0.5f;  // else this % of the final mesh's diagonal
  float distance_max_found = 0;
  float reference_diagonal = 0;
  bool distance_reference_known = false;
  bool distance_ready = false;
  int history_index = -1;  // -1: live; else index into the frame history
  size_t history_size = 0;
  // ASA (mirrors StreamControls until the user edits)
  bool asa_enabled = true;
  AsaOptions asa;
  // View-dependent ASA's pixel tolerance (0: ASA refines the whole mesh,
  // --view-independent, and the control is hidden).
  float pixel_tolerance = 0;
  // stream and renderer facts
  bool has_frame = false;
  bool paused = false;
  double rate_bytes_per_s = 0;
  double upload_ms = 0;
  float fps = 0;
  bool screenshot_requested = false;
  std::string message;      // last screenshot result
  float right_edge_px = 0;  // where the panel ends, in window pixels (for framing)
};

struct PanelActions {
  bool asa_changed = false;
  bool tolerance_changed = false;  // pixel_tolerance edited (StreamControls::set_pixel_tolerance)
  bool toggle_pause = false;
  bool frame_model = false;
  bool history_changed = false;
};

// Draws the panel for this ImGui frame. `latest` is the newest frame
// received, `shown` the one on screen (they differ while scrubbing history).
PanelActions draw_panel(PanelState& state, const DisplayFrame& latest, const DisplayFrame& shown,
                        uint32_t shown_vertices, uint32_t shown_triangles);

}  // namespace meshstream::client
