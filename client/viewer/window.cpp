// The live viewer window: GLFW + OpenGL 3.3 core + Dear ImGui. The render
// thread only polls the mailbox and uploads a mesh when its sequence
// changes; decoding and ASA stay on the client's threads, distances to the
// final mesh on a DistanceWorker.
#define GLFW_INCLUDE_NONE
#include "client/viewer/window.h"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "backends/imgui_impl_glfw.h"
#include "backends/imgui_impl_opengl3.h"
#include "client/viewer/frame_history.h"
#include "client/viewer/mesh_renderer.h"
#include "client/viewer/rgba_image.h"
#include "client/viewer/vertex_distances.h"
#include "client/viewer/viewer_panel.h"
#include "imgui.h"

namespace meshstream::client {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

std::string& glfw_last_error() {
  static std::string message;
  return message;
}

void on_glfw_error(int code, const char* description) {
  glfw_last_error() = std::string(description) + " (GLFW error " + std::to_string(code) + ")";
}

// Input gathered by GLFW callbacks (installed before ImGui's, which chains
// to them) and consumed once per frame.
struct PendingInput {
  float scroll = 0;
  std::vector<int> keys;  // pressed this frame
};

void on_scroll(GLFWwindow* window, double, double dy) {
  static_cast<PendingInput*>(glfwGetWindowUserPointer(window))->scroll += static_cast<float>(dy);
}

void on_key(GLFWwindow* window, int key, int, int action, int) {
  if (action == GLFW_PRESS) {
    static_cast<PendingInput*>(glfwGetWindowUserPointer(window))->keys.push_back(key);
  }
}

void* glfw_proc(const char* name) { return reinterpret_cast<void*>(glfwGetProcAddress(name)); }

// Reads the model part of the back buffer (before the panel is drawn).
RgbaImage read_back_buffer(const GlFunctions& gl, int width, int height) {
  RgbaImage image;
  image.width = width;
  image.height = height;
  image.rgba.resize(static_cast<size_t>(width) * height * 4);
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  gl.ReadBuffer(GL_BACK);
  gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, image.rgba.data());
  for (size_t i = 3; i < image.rgba.size(); i += 4) image.rgba[i] = 255;
  flip_rows(image);
  return image;
}

class GlfwSession {
 public:
  ~GlfwSession() {
    if (window_) glfwDestroyWindow(window_);
    glfwTerminate();
  }
  Status open(const ViewerOptions& options) {
    glfw_last_error().clear();
    glfwSetErrorCallback(&on_glfw_error);
    // No "viewer:" prefix in these messages: the client adds it once.
    if (!glfwInit()) {
      return make_error(ErrorCode::kUnsupported,
                        "no display to open a window on (" + glfw_last_error() +
                            "); use --snapshot FILE.png to render without one, or run under "
                            "xvfb-run");
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_SAMPLES, 4);
    window_ = glfwCreateWindow(std::max(options.width, 64), std::max(options.height, 64),
                               options.title.c_str(), nullptr, nullptr);
    if (!window_) {
      return make_error(ErrorCode::kUnsupported,
                        "cannot create an OpenGL 3.3 core window: " + glfw_last_error());
    }
    glfwMakeContextCurrent(window_);
    glfwSwapInterval(1);
    return {};
  }
  GLFWwindow* window() const { return window_; }

 private:
  GLFWwindow* window_ = nullptr;
};

class ImGuiSession {
 public:
  ~ImGuiSession() {
    if (opengl_) ImGui_ImplOpenGL3_Shutdown();
    if (glfw_) ImGui_ImplGlfw_Shutdown();
    if (context_) ImGui::DestroyContext(context_);
  }
  Status open(GLFWwindow* window) {
    context_ = ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini in the user's folder
    ImGui::StyleColorsDark();
    glfw_ = ImGui_ImplGlfw_InitForOpenGL(window, true);
    opengl_ = glfw_ && ImGui_ImplOpenGL3_Init("#version 330 core");
    if (!opengl_) return make_error(ErrorCode::kUnsupported, "Dear ImGui cannot start");
    return {};
  }

 private:
  ImGuiContext* context_ = nullptr;
  bool glfw_ = false, opengl_ = false;
};

}  // namespace

Result<ViewerReport> run_viewer_with_report(const ViewerOptions& options,
                                            LatestFrameMailbox& frames, StreamControls& controls,
                                            const std::vector<ScriptedCommand>& script) {
  GlfwSession glfw;
  if (Status opened = glfw.open(options); !opened) return tl::unexpected(opened.error());
  GLFWwindow* window = glfw.window();
  PendingInput input;
  glfwSetWindowUserPointer(window, &input);
  glfwSetScrollCallback(window, &on_scroll);
  glfwSetKeyCallback(window, &on_key);

  auto gl = load_gl_functions(&glfw_proc);
  if (!gl) return tl::unexpected(gl.error());
  auto renderer = MeshRenderer::create(*gl);
  if (!renderer) return tl::unexpected(renderer.error());
  ImGuiSession imgui;
  if (Status opened = imgui.open(window); !opened) return tl::unexpected(opened.error());

  PanelState panel;
  panel.coloring = static_cast<ColorMode>(std::clamp(options.initial_coloring, 0, 2));
  panel.wireframe = options.initial_wireframe;
  panel.asa_enabled = controls.asa_enabled();
  panel.asa = controls.asa_options();
  RenderStyle style;
  OrbitCamera camera;
  FrameHistory history;
  DistanceWorker distances;
  ViewerReport report;

  uint64_t seen = 0;
  DisplayFrame latest;  // newest frame received (for the panel)
  DisplayFrame shown;   // frame whose mesh is on the GPU
  bool has_shown = false, framed_once = false, want_frame = false;
  uint64_t distance_tag = 0;  // identifies `shown` for the distance worker
  int screenshot_counter = 0;
  RgbaImage last_model_image;
  double last_x = 0, last_y = 0;
  glfwGetCursorPos(window, &last_x, &last_y);
  auto loop_start = Clock::now();
  auto last_activity = loop_start;
  int last_window_w = 0, last_window_h = 0;

  auto show = [&](const DisplayFrame& frame) {
    std::shared_ptr<const Mesh> mesh = frame.display ? frame.display : frame.decoded;
    if (!mesh) return;
    // A bad index would make the GPU read out of bounds: refuse, say why.
    if (Status valid = validate_arrays(*mesh); !valid) {
      panel.message =
          "frame " + std::to_string(frame.sequence) + " not shown: " + valid.error().message;
      ++report.rejected_meshes;
      return;
    }
    auto start = Clock::now();
    // Shading follows the panel's crease angle (the ASA control), so the
    // edges ASA keeps sharp are also drawn sharp.
    renderer->upload(*mesh, frame.face_kind.get(), panel.asa.crease_degrees);
    double ms = ms_since(start);
    panel.upload_ms = ms;
    report.max_upload_ms = std::max(report.max_upload_ms, ms);
    ++report.meshes_uploaded;
    report.last_sequence_shown = frame.sequence;
    shown = frame;
    has_shown = true;
    panel.distance_ready = false;
    if (distances.has_reference()) distances.request(mesh, ++distance_tag);
    if (!framed_once) {
      want_frame = true;
      framed_once = true;
    }
  };

  while (!glfwWindowShouldClose(window)) {
    auto frame_start = Clock::now();
    glfwPollEvents();
    bool activity = false;  // anything that may change the picture

    // 1. New stream state: upload only when the sequence moved.
    if (auto frame = frames.take_newer(seen)) {
      seen = frame->sequence;
      activity = true;
      latest = *frame;
      panel.has_frame = true;
      history.add(latest);
      if (latest.final && latest.decoded && !distances.has_reference()) {
        distances.set_reference(latest.decoded);
        if (has_shown) {
          distances.request(shown.display ? shown.display : shown.decoded, ++distance_tag);
        }
      }
      if (panel.history_index < 0) show(latest);
    }
    if (auto answer = distances.take_result(); answer && answer->tag == distance_tag) {
      renderer->upload_distances(answer->distances);
      activity = true;
      ++report.distance_uploads;
      panel.distance_ready = true;
      panel.distance_max_found = answer->max;
      panel.distance_p98 = answer->p98;
      panel.reference_diagonal = answer->reference_diagonal;
    }
    panel.distance_reference_known = distances.has_reference();

    // 2. Input: mouse on the model unless the panel wants it; keys.
    int window_w = 0, window_h = 0, fb_w = 0, fb_h = 0;
    glfwGetWindowSize(window, &window_w, &window_h);
    glfwGetFramebufferSize(window, &fb_w, &fb_h);
    float aspect = fb_h > 0 ? static_cast<float>(fb_w) / static_cast<float>(fb_h) : 1.0f;
    double x = 0, y = 0;
    glfwGetCursorPos(window, &x, &y);
    const ImGuiIO& io = ImGui::GetIO();
    if (!io.WantCaptureMouse) {
      float dx = static_cast<float>(x - last_x), dy = static_cast<float>(y - last_y);
      bool left = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
      bool right = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
      bool middle = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS;
      bool shift = glfwGetKey(window, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                   glfwGetKey(window, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
      if (left && !shift) camera.orbit(dx, dy);
      if (right || middle || (left && shift)) camera.pan(dx, dy, static_cast<float>(window_h));
      if (input.scroll != 0) camera.zoom(input.scroll);
    }
    activity |= input.scroll != 0 || x != last_x || y != last_y || !input.keys.empty() ||
                glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS ||
                glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS ||
                window_w != last_window_w || window_h != last_window_h;
    last_window_w = window_w;
    last_window_h = window_h;
    input.scroll = 0;
    last_x = x;
    last_y = y;
    std::vector<ScriptedCommand> commands;
    for (const ScriptedCommand& c : script) {
      if (c.at_frame == report.frames_drawn) commands.push_back(c);
    }
    if (!io.WantCaptureKeyboard) {
      for (int key : input.keys) {
        ScriptedCommand c;
        switch (key) {
          case GLFW_KEY_F:
            c.command = ViewerCommand::kFrameModel;
            break;
          case GLFW_KEY_W:
            c.command = ViewerCommand::kToggleWireframe;
            break;
          case GLFW_KEY_1:
            c.command = ViewerCommand::kColorShaded;
            break;
          case GLFW_KEY_2:
            c.command = ViewerCommand::kColorAsaKinds;
            break;
          case GLFW_KEY_3:
            c.command = ViewerCommand::kColorDistance;
            break;
          case GLFW_KEY_SPACE:
            c.command = ViewerCommand::kTogglePause;
            break;
          case GLFW_KEY_S:
            c.command = ViewerCommand::kScreenshot;
            break;
          case GLFW_KEY_ESCAPE:
            c.command = ViewerCommand::kClose;
            break;
          default:
            continue;
        }
        commands.push_back(c);
      }
    }
    activity |= !commands.empty();
    for (const ScriptedCommand& c : commands) {
      switch (c.command) {
        case ViewerCommand::kFrameModel:
          want_frame = true;
          break;
        case ViewerCommand::kToggleWireframe:
          panel.wireframe = !panel.wireframe;
          break;
        case ViewerCommand::kColorShaded:
          panel.coloring = ColorMode::kShaded;
          break;
        case ViewerCommand::kColorAsaKinds:
          panel.coloring = ColorMode::kAsaKinds;
          break;
        case ViewerCommand::kColorDistance:
          panel.coloring = ColorMode::kDistance;
          break;
        case ViewerCommand::kTogglePause:
          controls.paused() ? controls.resume() : controls.pause();
          break;
        case ViewerCommand::kScreenshot:
          panel.screenshot_requested = true;
          break;
        case ViewerCommand::kClose:
          glfwSetWindowShouldClose(window, GLFW_TRUE);
          break;
        case ViewerCommand::kSetAsa:
          panel.asa_enabled = c.asa_enabled;
          panel.asa = c.asa;
          controls.set_asa(panel.asa_enabled, panel.asa);
          break;
      }
    }
    input.keys.clear();
    if (want_frame && has_shown && report.frames_drawn > 0) {  // after the panel has a size
      // Frame into the part of the window right of the panel: fit the model
      // to that width, then slide it over by half the panel.
      const auto& mesh = shown.display ? shown.display : shown.decoded;
      float covered = std::clamp(panel.right_edge_px, 0.0f, 0.5f * static_cast<float>(window_w));
      float free_aspect =
          window_h > 0 ? (static_cast<float>(window_w) - covered) / static_cast<float>(window_h)
                       : aspect;
      camera.frame(*mesh, std::min(aspect, free_aspect));
      camera.pan(covered / 2, 0, static_cast<float>(window_h));
      want_frame = false;
    }

    // 3. The model, then (optionally) a screenshot of it, then the panel.
    style.coloring = panel.coloring;
    style.wireframe = panel.wireframe;
    style.distance_max = panel.distance_auto ? std::max(panel.distance_p98, 1e-12f)
                                             : panel.distance_max_percent / 100.0f *
                                                   std::max(panel.reference_diagonal, 1e-12f);
    gl->BindFramebuffer(GL_FRAMEBUFFER, 0);
    renderer->draw(camera, fb_w, fb_h, style);
    bool last_frame =
        (options.exit_after_frames != 0 && report.frames_drawn + 1 >= options.exit_after_frames) ||
        (options.exit_after_records != 0 && has_shown &&
         shown.records_decoded >= options.exit_after_records);
    if (panel.screenshot_requested && fb_w > 0 && fb_h > 0) {
      panel.screenshot_requested = false;
      std::string path = options.screenshot_dir + "/meshstream-screenshot-" +
                         std::to_string(shown.sequence) + "-" +
                         std::to_string(++screenshot_counter) + ".png";
      Status written = write_png(path, read_back_buffer(*gl, fb_w, fb_h));
      panel.message = written ? "saved " + path : written.error().message;
      if (written) report.screenshots.push_back(path);
    }
    bool capture_exit = (last_frame || glfwWindowShouldClose(window)) &&
                        !options.exit_screenshot.empty() && fb_w > 0 && fb_h > 0;
    if (capture_exit && !options.exit_screenshot_with_panel) {
      last_model_image = read_back_buffer(*gl, fb_w, fb_h);
    }

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    panel.fps = io.Framerate;
    panel.paused = controls.paused();
    panel.rate_bytes_per_s = controls.current_rate_bytes_per_s();
    panel.history_size = history.size();
    PanelActions actions =
        draw_panel(panel, latest, shown, has_shown ? renderer->vertex_count() : 0,
                   has_shown ? renderer->triangle_count() : 0);
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    if (capture_exit && options.exit_screenshot_with_panel) {
      last_model_image = read_back_buffer(*gl, fb_w, fb_h);
    }
    glfwSwapBuffers(window);
    ++report.frames_drawn;

    // 4. What the panel asked for.
    if (actions.asa_changed) controls.set_asa(panel.asa_enabled, panel.asa);
    if (actions.toggle_pause) controls.paused() ? controls.resume() : controls.pause();
    if (actions.frame_model) want_frame = true;
    if (actions.history_changed && !history.empty()) {
      if (panel.history_index < 0) {
        show(history.newest());
      } else {
        size_t i = std::min(static_cast<size_t>(panel.history_index), history.size() - 1);
        show(history[i]);
      }
    }

    if (last_frame) break;
    // Xvfb and some drivers ignore the swap interval: cap at ~60 frames per
    // second, and at 20 once nothing has happened for half a second, so an
    // idle viewer on a software rasterizer leaves the cores to decoding, ASA
    // and the distance worker. Any input event wakes the wait at once.
    if (activity) last_activity = Clock::now();
    double frame_budget_ms = ms_since(last_activity) > 500.0 ? 50.0 : 1000.0 / 60.0;
    double spare_ms = frame_budget_ms - ms_since(frame_start);
    if (spare_ms > 1.0) glfwWaitEventsTimeout(spare_ms / 1000.0);
  }
  report.final_coloring = static_cast<int>(panel.coloring);
  report.final_wireframe = panel.wireframe;
  report.mean_frame_ms = report.frames_drawn ? ms_since(loop_start) / report.frames_drawn : 0;
  if (!options.exit_screenshot.empty()) {
    if (last_model_image.rgba.empty()) {
      return make_error(ErrorCode::kIo, options.exit_screenshot + ": no frame was drawn");
    }
    if (Status written = write_png(options.exit_screenshot, last_model_image); !written) {
      return tl::unexpected(written.error());
    }
  }
  return report;
}

Status run_viewer(const ViewerOptions& given, LatestFrameMailbox& frames,
                  StreamControls& controls) {
  ViewerOptions options = given;
  auto env = [](const char* name) -> std::string {
    const char* value = std::getenv(name);
    return value ? value : "";
  };
  if (options.exit_screenshot.empty() && !env("MESHSTREAM_VIEWER_CAPTURE").empty()) {
    options.exit_screenshot = env("MESHSTREAM_VIEWER_CAPTURE");
    options.exit_screenshot_with_panel = true;
  }
  if (options.initial_coloring == 0) {
    std::string coloring = env("MESHSTREAM_VIEWER_COLORING");
    options.initial_coloring = coloring == "kinds" ? 1 : coloring == "distance" ? 2 : 0;
  }
  if (!options.initial_wireframe)
    options.initial_wireframe = env("MESHSTREAM_VIEWER_WIREFRAME") == "1";
  auto report = run_viewer_with_report(options, frames, controls);
  if (!report) return tl::unexpected(report.error());
  return {};
}

}  // namespace meshstream::client
