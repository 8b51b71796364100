#include "client/viewer/viewer_panel.h"

#include <cstdio>

#include "imgui.h"

namespace meshstream::client {
namespace {

std::string human_bytes(double bytes) {
  char text[32];
  if (bytes >= 1e6) {
    std::snprintf(text, sizeof text, "%.2f MB", bytes / 1e6);
  } else if (bytes >= 1e3) {
    std::snprintf(text, sizeof text, "%.1f kB", bytes / 1e3);
  } else {
    std::snprintf(text, sizeof text, "%.0f B", bytes);
  }
  return text;
}

uint32_t vertices_of(const std::shared_ptr<const Mesh>& mesh) {
  return mesh ? mesh->vertex_count() : 0;
}
uint32_t faces_of(const std::shared_ptr<const Mesh>& mesh) { return mesh ? mesh->face_count() : 0; }

}  // namespace

PanelActions draw_panel(PanelState& state, const DisplayFrame& latest, const DisplayFrame& shown,
                        uint32_t shown_vertices, uint32_t shown_triangles) {
  PanelActions actions;
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(330, 0), ImGuiCond_FirstUseEver);
  ImGui::Begin("meshstream", nullptr, ImGuiWindowFlags_AlwaysAutoResize);

  // Stream.
  if (!state.has_frame) {
    ImGui::TextUnformatted("waiting for the first mesh...");
  } else {
    float fraction = latest.bytes_total ? static_cast<float>(latest.bytes_received) /
                                              static_cast<float>(latest.bytes_total)
                                        : 0.0f;
    std::string overlay = human_bytes(static_cast<double>(latest.bytes_received)) + " / " +
                          human_bytes(static_cast<double>(latest.bytes_total));
    ImGui::ProgressBar(fraction, ImVec2(-1, 0), overlay.c_str());
    ImGui::Text("records   %u / %u%s", latest.records_decoded, latest.records_total,
                latest.final ? "  (final)" : "");
    ImGui::Text("decoded   %u vertices, %u triangles", vertices_of(latest.decoded),
                faces_of(latest.decoded));
    ImGui::Text("display   %u vertices, %u triangles", vertices_of(latest.display),
                faces_of(latest.display));
    ImGui::Text("rate      %s/s%s", human_bytes(state.rate_bytes_per_s).c_str(),
                state.paused ? "  (paused)" : "");
    ImGui::Text("decode %.2f ms   ASA %.2f ms   merged %u", latest.decode_ms, latest.asa_ms,
                latest.coalesced_updates);
  }
  ImGui::Text("%.0f FPS   upload %.2f ms", state.fps, state.upload_ms);
  if (ImGui::Button(state.paused ? "Resume stream" : "Pause stream")) actions.toggle_pause = true;
  ImGui::SameLine();
  if (ImGui::Button("Screenshot")) state.screenshot_requested = true;
  if (!state.message.empty()) ImGui::TextWrapped("%s", state.message.c_str());

  // ASA: applied when a control is released, not on every drag step, so
  // the client re-runs ASA once per decision.
  if (ImGui::CollapsingHeader("ASA post-processing", ImGuiTreeNodeFlags_DefaultOpen)) {
    if (ImGui::Checkbox("enabled", &state.asa_enabled)) actions.asa_changed = true;
    ImGui::SliderInt("levels", &state.asa.levels, 1, 3);
    actions.asa_changed |= ImGui::IsItemDeactivatedAfterEdit();
    ImGui::SliderFloat("t (flatness)", &state.asa.flatness, 0.0f, 1.0f, "%.3f");
    actions.asa_changed |= ImGui::IsItemDeactivatedAfterEdit();
    int rule = state.asa.rule == ButterflyRule::kProjection ? 1 : 0;
    if (ImGui::Combo("rule", &rule, "Zorin (3-D)\0projection (planar)\0")) {
      state.asa.rule = rule == 1 ? ButterflyRule::kProjection : ButterflyRule::kZorin;
      actions.asa_changed = true;
    }
    ImGui::SliderFloat("crease angle", &state.asa.crease_degrees, 0.0f, 120.0f, "%.0f deg");
    actions.asa_changed |= ImGui::IsItemDeactivatedAfterEdit();
    if (ImGui::Checkbox("uniform (split all)", &state.asa.uniform)) actions.asa_changed = true;
    if (state.pixel_tolerance > 0) {
      // Refines only edges larger than this on screen, for the window's camera.
      ImGui::SliderFloat("pixel tolerance", &state.pixel_tolerance, 0.25f, 32.0f, "%.2f px",
                         ImGuiSliderFlags_Logarithmic);
      actions.tolerance_changed |= ImGui::IsItemDeactivatedAfterEdit();
      if (latest.pixel_tolerance > 0)
        ImGui::Text("used %.2f px%s", latest.pixel_tolerance,
                    latest.budget_limited ? "  (raised: face budget)" : "");
    } else {
      ImGui::TextUnformatted("view-independent (whole mesh)");
    }
  }

  // Display.
  if (ImGui::CollapsingHeader("Display", ImGuiTreeNodeFlags_DefaultOpen)) {
    int coloring = static_cast<int>(state.coloring);
    if (ImGui::Combo("colour", &coloring, "shaded\0what ASA did\0distance to final\0")) {
      state.coloring = static_cast<ColorMode>(coloring);
    }
    if (state.coloring == ColorMode::kShaded && state.mesh_has_surface) {
      int surface = static_cast<int>(state.surface);
      if (ImGui::Combo("surface", &surface, "lit\0base colour\0texture\0")) {
        state.surface = static_cast<SurfaceMode>(surface);
      }
    }
    if (state.coloring == ColorMode::kAsaKinds) {
      ImGui::TextColored(ImVec4(0.55f, 0.62f, 0.75f, 1), "untouched");
      ImGui::SameLine();
      ImGui::TextColored(ImVec4(0.95f, 0.55f, 0.15f, 1), "target");
      ImGui::SameLine();
      ImGui::TextColored(ImVec4(0.35f, 0.80f, 0.35f, 1), "bisected");
    }
    if (state.coloring == ColorMode::kDistance) {
      if (!state.distance_reference_known) {
        ImGui::TextWrapped(
            "the final mesh is not known yet: distances appear when the stream ends");
      } else if (!state.distance_ready) {
        ImGui::TextUnformatted("computing distances...");
      } else {
        float diagonal = state.reference_diagonal > 0 ? state.reference_diagonal : 1.0f;
        ImGui::Text("max %.3g (%.3f%% of diagonal)", state.distance_max_found,
                    100.0f * state.distance_max_found / diagonal);
      }
      ImGui::Checkbox("red at the 98th percentile", &state.distance_auto);
      if (!state.distance_auto) {
        ImGui::SliderFloat("red at % diagonal", &state.distance_max_percent, 0.01f, 5.0f, "%.2f",
                           ImGuiSliderFlags_Logarithmic);
      }
    }
    ImGui::Checkbox("wireframe (W)", &state.wireframe);
    ImGui::SameLine();
    if (ImGui::Button("frame model (F)")) actions.frame_model = true;
    if (state.history_size > 1) {
      int last = static_cast<int>(state.history_size) - 1;
      int position = state.history_index < 0 ? last + 1 : state.history_index;
      const char* label = state.history_index < 0 ? "live" : "frame %d";
      if (ImGui::SliderInt("history", &position, 0, last + 1, label)) {
        state.history_index = position > last ? -1 : position;
        actions.history_changed = true;
      }
      if (state.history_index >= 0) {
        ImGui::Text("showing record %u: %u vertices, %u triangles", shown.records_decoded,
                    shown_vertices, shown_triangles);
      }
    }
  }
  ImGui::TextDisabled("drag: orbit  shift/right drag: pan  wheel: zoom");
  ImGui::TextDisabled("1/2/3 colour  W wire  F frame  space pause  S shot");
  state.right_edge_px = ImGui::GetWindowPos().x + ImGui::GetWindowWidth();
  ImGui::End();
  return actions;
}

}  // namespace meshstream::client
