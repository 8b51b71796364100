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
#include <optional>
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

// Window size, framebuffer size and cursor of one frame.
struct FrameGeometry {
  int window_w = 0, window_h = 0, fb_w = 0, fb_h = 0;
  float aspect = 1.0f;
  double x = 0, y = 0;
};

// What a key asks for; false for keys the viewer does not use.
bool command_for_key(int key, ViewerCommand& command) {
  switch (key) {
    case GLFW_KEY_F:
      command = ViewerCommand::kFrameModel;
      return true;
    case GLFW_KEY_W:
      command = ViewerCommand::kToggleWireframe;
      return true;
    case GLFW_KEY_1:
      command = ViewerCommand::kColorShaded;
      return true;
    case GLFW_KEY_2:
      command = ViewerCommand::kColorAsaKinds;
      return true;
    case GLFW_KEY_3:
      command = ViewerCommand::kColorDistance;
      return true;
    case GLFW_KEY_SPACE:
      command = ViewerCommand::kTogglePause;
      return true;
    case GLFW_KEY_S:
      command = ViewerCommand::kScreenshot;
      return true;
    case GLFW_KEY_ESCAPE:
      command = ViewerCommand::kClose;
      return true;
    default:
      return false;
  }
}

// The window's loop once GLFW, OpenGL, the renderer and ImGui are up: per
// frame, (1) new stream state, (2) input and commands, (3) the model, a
// screenshot, the panel, (4) what the panel asked for, then a wait that
// caps the frame rate.
class ViewerLoop {
 public:
  ViewerLoop(const ViewerOptions& options, LatestFrameMailbox& frames, StreamControls& controls,
             const std::vector<ScriptedCommand>& script, GLFWwindow* window, const GlFunctions& gl,
             MeshRenderer& renderer, PendingInput& input)
      : options_(options),
        frames_(frames),
        controls_(controls),
        script_(script),
        window_(window),
        gl_(gl),
        renderer_(renderer),
        input_(input) {
    panel_.coloring = static_cast<ColorMode>(std::clamp(options.initial_coloring, 0, 2));
    panel_.wireframe = options.initial_wireframe;
    panel_.asa_enabled = controls.asa_enabled();
    panel_.asa = controls.asa_options();
    panel_.pixel_tolerance = controls.pixel_tolerance();
    glfwGetCursorPos(window, &last_x_, &last_y_);
  }

  Result<ViewerReport> run() {
    const auto loop_start = Clock::now();
    last_activity_ = loop_start;
    while (!glfwWindowShouldClose(window_)) {
      const auto frame_start = Clock::now();
      glfwPollEvents();
      // The client closed the mailbox (Ctrl-C): this frame is the last.
      if (frames_.closed()) glfwSetWindowShouldClose(window_, GLFW_TRUE);
      bool activity = take_stream_state();  // anything that may change the picture
      const FrameGeometry g = read_geometry();
      activity |= steer_camera(g);
      const std::vector<ScriptedCommand> commands = commands_this_frame();
      activity |= !commands.empty();
      for (const ScriptedCommand& c : commands) apply(c);
      input_.keys.clear();
      frame_model_if_asked(g);
      activity |= orbit_if_scripted();
      send_camera(g);
      const bool last_frame = draw_model(g);
      const PanelActions actions = draw_panel_and_swap(g, last_frame);
      apply_panel_actions(actions);
      count_frame(frame_start);
      if (last_frame) break;
      wait_for_next_frame(frame_start, activity);
    }
    return finish(loop_start);
  }

 private:
  void show(const DisplayFrame& frame) {
    std::shared_ptr<const Mesh> mesh = frame.display ? frame.display : frame.decoded;
    if (!mesh) return;
    // A bad index would make the GPU read out of bounds: refuse, say why.
    if (Status valid = validate_arrays(*mesh); !valid) {
      panel_.message =
          "frame " + std::to_string(frame.sequence) + " not shown: " + valid.error().message;
      ++report_.rejected_meshes;
      return;
    }
    // Uploaded before the next draw, culled or whole for that frame's camera
    // (upload_for_camera).
    report_.last_sequence_shown = frame.sequence;
    shown_ = frame;
    has_shown_ = true;
    if (!framed_once_) {
      want_frame_ = true;
      framed_once_ = true;
    }
  }

  void upload(const std::shared_ptr<const Mesh>& mesh, const std::vector<FaceKind>* kinds) {
    auto start = Clock::now();
    // Shading follows the panel's crease angle (the ASA control), so the
    // edges ASA keeps sharp are also drawn sharp.
    renderer_.upload(*mesh, kinds, panel_.asa.crease_degrees);
    double ms = ms_since(start);
    panel_.upload_ms = ms;
    report_.max_upload_ms = std::max(report_.max_upload_ms, ms);
    ++report_.meshes_uploaded;
    uploaded_ = mesh;
    panel_.distance_ready = false;
    ++distance_tag_;  // the distances of what was on the GPU no longer fit
    request_distances_if_shown();
  }

  // Distances to the final mesh are worth their O(V log F) only while the
  // distance colouring shows them: a re-cull each frame of an orbit would
  // otherwise keep the worker busy for nothing.
  void request_distances_if_shown() {
    if (!uploaded_ || !distances_.has_reference() || panel_.coloring != ColorMode::kDistance ||
        requested_tag_ == distance_tag_)
      return;
    distances_.request(uploaded_, distance_tag_);
    requested_tag_ = distance_tag_;
  }

  // 3. Before drawing: what the pipeline culled for its camera (view-dependent
  // mode) while this camera is within the cull's region, else the frame's
  // whole display. A culled mesh lacks faces a camera outside that region
  // might see; culling again here would cost O(V + F) on the render thread at
  // every step of an orbit (hundreds of ms on a 3M-face display), so the
  // window draws the whole display (the same picture) until the pipeline's
  // next frame brings a cull for the camera it was sent.
  void upload_for_camera(const FrameGeometry& g) {
    request_distances_if_shown();  // the colouring may have just changed
    if (!has_shown_) return;
    const std::shared_ptr<const Mesh>& whole = shown_.display ? shown_.display : shown_.decoded;
    bool use_drawn = shown_.drawn != nullptr;
    if (use_drawn && !shown_.cull.everything) {
      use_drawn =
          g.fb_w > 0 && g.fb_h > 0 &&
          cull_valid_for(shown_.cull, camera_.asa_camera(g.fb_w, g.fb_h), camera_.near_plane());
    }
    const std::shared_ptr<const Mesh>& target = use_drawn ? shown_.drawn : whole;
    if (!target || target == uploaded_) return;
    if (!use_drawn && shown_.drawn && shown_.drawn != whole) ++report_.whole_display_uploads;
    upload(target, use_drawn ? shown_.drawn_face_kind.get() : shown_.face_kind.get());
  }

  // 1. New stream state: upload only when the sequence moved; distances to
  // the final mesh when the worker has them.
  bool take_stream_state() {
    bool activity = false;
    if (auto frame = frames_.take_newer(seen_)) {
      seen_ = frame->sequence;
      activity = true;
      latest_ = *frame;
      panel_.has_frame = true;
      history_.add(latest_);
      if (latest_.final && latest_.decoded && !distances_.has_reference()) {
        distances_.set_reference(latest_.decoded);
        if (has_shown_) {
          ++distance_tag_;
          request_distances_if_shown();
        }
      }
      if (panel_.history_index < 0) show(latest_);
    }
    if (auto answer = distances_.take_result(); answer && answer->tag == distance_tag_) {
      renderer_.upload_distances(answer->distances);
      activity = true;
      ++report_.distance_uploads;
      panel_.distance_ready = true;
      panel_.distance_max_found = answer->max;
      panel_.distance_p98 = answer->p98;
      panel_.reference_diagonal = answer->reference_diagonal;
    }
    panel_.distance_reference_known = distances_.has_reference();
    return activity;
  }

  FrameGeometry read_geometry() const {
    FrameGeometry g;
    glfwGetWindowSize(window_, &g.window_w, &g.window_h);
    glfwGetFramebufferSize(window_, &g.fb_w, &g.fb_h);
    g.aspect = g.fb_h > 0 ? static_cast<float>(g.fb_w) / static_cast<float>(g.fb_h) : 1.0f;
    glfwGetCursorPos(window_, &g.x, &g.y);
    return g;
  }

  // 2a. The mouse moves the camera unless the panel wants it.
  bool steer_camera(const FrameGeometry& g) {
    const ImGuiIO& io = ImGui::GetIO();
    if (!io.WantCaptureMouse) {
      float dx = static_cast<float>(g.x - last_x_), dy = static_cast<float>(g.y - last_y_);
      bool left = glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
      bool right = glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
      bool middle = glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS;
      bool shift = glfwGetKey(window_, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                   glfwGetKey(window_, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
      if (left && !shift) camera_.orbit(dx, dy);
      if (right || middle || (left && shift)) camera_.pan(dx, dy, static_cast<float>(g.window_h));
      if (input_.scroll != 0) camera_.zoom(input_.scroll);
    }
    const bool activity = input_.scroll != 0 || g.x != last_x_ || g.y != last_y_ ||
                          !input_.keys.empty() ||
                          glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS ||
                          glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS ||
                          g.window_w != last_window_w_ || g.window_h != last_window_h_;
    last_window_w_ = g.window_w;
    last_window_h_ = g.window_h;
    input_.scroll = 0;
    last_x_ = g.x;
    last_y_ = g.y;
    return activity;
  }

  // 2b. Scripted commands for this frame, then the keys (unless the panel
  // has the keyboard).
  std::vector<ScriptedCommand> commands_this_frame() const {
    std::vector<ScriptedCommand> commands;
    for (const ScriptedCommand& c : script_) {
      if (c.at_frame == report_.frames_drawn) commands.push_back(c);
    }
    if (!ImGui::GetIO().WantCaptureKeyboard) {
      for (int key : input_.keys) {
        ScriptedCommand c;
        if (command_for_key(key, c.command)) commands.push_back(c);
      }
    }
    return commands;
  }

  void apply(const ScriptedCommand& c) {
    switch (c.command) {
      case ViewerCommand::kFrameModel:
        want_frame_ = true;
        break;
      case ViewerCommand::kToggleWireframe:
        panel_.wireframe = !panel_.wireframe;
        break;
      case ViewerCommand::kColorShaded:
        panel_.coloring = ColorMode::kShaded;
        break;
      case ViewerCommand::kColorAsaKinds:
        panel_.coloring = ColorMode::kAsaKinds;
        break;
      case ViewerCommand::kColorDistance:
        panel_.coloring = ColorMode::kDistance;
        break;
      case ViewerCommand::kTogglePause:
        controls_.paused() ? controls_.resume() : controls_.pause();
        break;
      case ViewerCommand::kScreenshot:
        panel_.screenshot_requested = true;
        break;
      case ViewerCommand::kClose:
        glfwSetWindowShouldClose(window_, GLFW_TRUE);
        break;
      case ViewerCommand::kSetAsa:
        panel_.asa_enabled = c.asa_enabled;
        panel_.asa = c.asa;
        controls_.set_asa(panel_.asa_enabled, panel_.asa);
        break;
    }
  }

  // 2d. View-dependent ASA refines for the window's camera: hand it to the
  // pipeline when it moved (once the model is framed). The pipeline re-runs
  // ASA on its own thread; this frame draws the display mesh it has.
  void send_camera(const FrameGeometry& g) {
    if (panel_.pixel_tolerance <= 0 || !framed_once_ || want_frame_ || g.fb_w <= 0 || g.fb_h <= 0)
      return;
    const AsaCamera camera = camera_.asa_camera(g.fb_w, g.fb_h);
    if (sent_camera_ && camera.eye == sent_camera_->eye && camera.target == sent_camera_->target &&
        camera.fov_degrees == sent_camera_->fov_degrees && camera.width == sent_camera_->width &&
        camera.height == sent_camera_->height)
      return;
    controls_.set_view_camera(camera);
    sent_camera_ = camera;
    ++report_.cameras_sent;
  }

  // MESHSTREAM_VIEWER_ORBIT=DEG: a scripted orbit of DEG degrees per frame
  // (for captures and the view-dependent benchmark under Xvfb).
  bool orbit_if_scripted() {
    if (options_.orbit_degrees_per_frame == 0 || !framed_once_ || want_frame_) return false;
    camera_.yaw -= options_.orbit_degrees_per_frame * 3.14159265f / 180.0f;
    return true;
  }

  // 2c. Frame into the part of the window right of the panel: fit the
  // model to that width, then slide it over by half the panel.
  void frame_model_if_asked(const FrameGeometry& g) {
    if (!(want_frame_ && has_shown_ && report_.frames_drawn > 0)) return;  // panel has a size
    const auto& mesh = shown_.display ? shown_.display : shown_.decoded;
    float covered = std::clamp(panel_.right_edge_px, 0.0f, 0.5f * static_cast<float>(g.window_w));
    float free_aspect =
        g.window_h > 0 ? (static_cast<float>(g.window_w) - covered) / static_cast<float>(g.window_h)
                       : g.aspect;
    camera_.frame(*mesh, std::min(g.aspect, free_aspect));
    camera_.pan(covered / 2, 0, static_cast<float>(g.window_h));
    want_frame_ = false;
  }

  // 3a. The model, then (optionally) a screenshot of it. True when this is
  // the last frame (options.exit_after_frames / exit_after_records).
  bool draw_model(const FrameGeometry& g) {
    style_.coloring = panel_.coloring;
    style_.surface = panel_.surface;
    panel_.mesh_has_surface = renderer_.has_colors() || renderer_.has_texture();
    style_.wireframe = panel_.wireframe;
    style_.distance_max = panel_.distance_auto ? std::max(panel_.distance_p98, 1e-12f)
                                               : panel_.distance_max_percent / 100.0f *
                                                     std::max(panel_.reference_diagonal, 1e-12f);
    upload_for_camera(g);
    gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
    renderer_.draw(camera_, g.fb_w, g.fb_h, style_);
    const bool last_frame = (options_.exit_after_frames != 0 &&
                             report_.frames_drawn + 1 >= options_.exit_after_frames) ||
                            (options_.exit_after_records != 0 && has_shown_ &&
                             shown_.records_decoded >= options_.exit_after_records);
    if (panel_.screenshot_requested && g.fb_w > 0 && g.fb_h > 0) {
      panel_.screenshot_requested = false;
      std::string path = options_.screenshot_dir + "/meshstream-screenshot-" +
                         std::to_string(shown_.sequence) + "-" +
                         std::to_string(++screenshot_counter_) + ".png";
      Status written = write_png(path, read_back_buffer(gl_, g.fb_w, g.fb_h));
      panel_.message = written ? "saved " + path : written.error().message;
      if (written) report_.screenshots.push_back(path);
    }
    if (capture_exit(g, last_frame) && !options_.exit_screenshot_with_panel) {
      last_model_image_ = read_back_buffer(gl_, g.fb_w, g.fb_h);
    }
    return last_frame;
  }

  // The exit screenshot is taken on the last frame (or once the window is
  // asked to close).
  bool capture_exit(const FrameGeometry& g, bool last_frame) const {
    return (last_frame || glfwWindowShouldClose(window_)) && !options_.exit_screenshot.empty() &&
           g.fb_w > 0 && g.fb_h > 0;
  }

  // 3b. The panel over the model, then the swap.
  PanelActions draw_panel_and_swap(const FrameGeometry& g, bool last_frame) {
    const bool capture = capture_exit(g, last_frame);
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    panel_.fps = ImGui::GetIO().Framerate;
    panel_.paused = controls_.paused();
    panel_.rate_bytes_per_s = controls_.current_rate_bytes_per_s();
    panel_.history_size = history_.size();
    PanelActions actions =
        draw_panel(panel_, latest_, shown_, has_shown_ ? renderer_.vertex_count() : 0,
                   has_shown_ ? renderer_.triangle_count() : 0);
    ImGui::Render();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    if (capture && options_.exit_screenshot_with_panel) {
      last_model_image_ = read_back_buffer(gl_, g.fb_w, g.fb_h);
    }
    glfwSwapBuffers(window_);
    ++report_.frames_drawn;
    return actions;
  }

  // What the report says of each frame: was a mesh on screen, how long
  // the frame's own work took.
  void count_frame(Clock::time_point frame_start) {
    if (!has_shown_)
      ++report_.frames_before_first_mesh;
    else if (renderer_.triangle_count() == 0)
      ++report_.frames_without_mesh;
    report_.max_frame_ms = std::max(report_.max_frame_ms, ms_since(frame_start));
  }

  // 4. What the panel asked for.
  void apply_panel_actions(const PanelActions& actions) {
    if (actions.asa_changed) controls_.set_asa(panel_.asa_enabled, panel_.asa);
    if (actions.tolerance_changed) controls_.set_pixel_tolerance(panel_.pixel_tolerance);
    if (actions.toggle_pause) controls_.paused() ? controls_.resume() : controls_.pause();
    if (actions.frame_model) want_frame_ = true;
    if (actions.history_changed && !history_.empty()) {
      if (panel_.history_index < 0) {
        show(history_.newest());
      } else {
        size_t i = std::min(static_cast<size_t>(panel_.history_index), history_.size() - 1);
        show(history_[i]);
      }
    }
  }

  // Xvfb and some drivers ignore the swap interval: cap at ~60 frames per
  // second, and at 20 once nothing has happened for half a second, so an
  // idle viewer on a software rasterizer leaves the cores to decoding, ASA
  // and the distance worker. Any input event wakes the wait at once.
  void wait_for_next_frame(Clock::time_point frame_start, bool activity) {
    if (activity) last_activity_ = Clock::now();
    double frame_budget_ms = ms_since(last_activity_) > 500.0 ? 50.0 : 1000.0 / 60.0;
    double spare_ms = frame_budget_ms - ms_since(frame_start);
    if (spare_ms > 1.0) glfwWaitEventsTimeout(spare_ms / 1000.0);
  }

  // The report, and the exit screenshot if one was asked for.
  Result<ViewerReport> finish(Clock::time_point loop_start) {
    report_.final_coloring = static_cast<int>(panel_.coloring);
    report_.final_wireframe = panel_.wireframe;
    report_.mean_frame_ms = report_.frames_drawn ? ms_since(loop_start) / report_.frames_drawn : 0;
    if (!options_.exit_screenshot.empty()) {
      if (last_model_image_.rgba.empty()) {
        return make_error(ErrorCode::kIo, options_.exit_screenshot + ": no frame was drawn");
      }
      if (Status written = write_png(options_.exit_screenshot, last_model_image_); !written) {
        return tl::unexpected(written.error());
      }
    }
    return report_;
  }

  const ViewerOptions& options_;
  LatestFrameMailbox& frames_;
  StreamControls& controls_;
  const std::vector<ScriptedCommand>& script_;
  GLFWwindow* window_;
  const GlFunctions& gl_;
  MeshRenderer& renderer_;
  PendingInput& input_;

  PanelState panel_;
  RenderStyle style_;
  OrbitCamera camera_;
  FrameHistory history_;
  DistanceWorker distances_;
  ViewerReport report_;

  uint64_t seen_ = 0;
  DisplayFrame latest_;  // newest frame received (for the panel)
  DisplayFrame shown_;   // frame whose mesh is on the GPU
  std::shared_ptr<const Mesh>
      uploaded_;  // the mesh on the GPU: shown_'s drawn or its whole display
  bool has_shown_ = false, framed_once_ = false, want_frame_ = false;
  uint64_t distance_tag_ = 0;   // identifies `shown_` for the distance worker
  uint64_t requested_tag_ = 0;  // the tag last asked of the worker
  int screenshot_counter_ = 0;
  RgbaImage last_model_image_;
  double last_x_ = 0, last_y_ = 0;
  Clock::time_point last_activity_;
  int last_window_w_ = 0, last_window_h_ = 0;
  std::optional<AsaCamera> sent_camera_;  // the last camera handed to the pipeline
};

}  // namespace

// Opens the window (GLFW, OpenGL functions, the renderer, ImGui), then runs
// the loop.
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

  ViewerLoop loop(options, frames, controls, script, window, *gl, *renderer, input);
  return loop.run();
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
  if (options.orbit_degrees_per_frame == 0 && !env("MESHSTREAM_VIEWER_ORBIT").empty())
    options.orbit_degrees_per_frame = std::strtof(env("MESHSTREAM_VIEWER_ORBIT").c_str(), nullptr);
  auto report = run_viewer_with_report(options, frames, controls);
  if (!report) return tl::unexpected(report.error());
  if (options.orbit_degrees_per_frame != 0) {
    // The scripted orbit is a benchmark (bench/REPORT.md, view-dependent
    // ASA): say whether the window ever lacked a mesh and how long frames took.
    std::fprintf(
        stderr,
        "viewer: %llu frames (mean %.1f ms, longest %.1f ms of work), %llu without a "
        "mesh once one was shown, %llu before the first; %llu cameras sent, %llu meshes "
        "uploaded (longest upload %.1f ms), %llu whole displays for a camera outside the cull\n",
        static_cast<unsigned long long>(report->frames_drawn), report->mean_frame_ms,
        report->max_frame_ms, static_cast<unsigned long long>(report->frames_without_mesh),
        static_cast<unsigned long long>(report->frames_before_first_mesh),
        static_cast<unsigned long long>(report->cameras_sent),
        static_cast<unsigned long long>(report->meshes_uploaded), report->max_upload_ms,
        static_cast<unsigned long long>(report->whole_display_uploads));
  }
  return {};
}

}  // namespace meshstream::client
