#include "client/viewer/offscreen.h"

#include <GL/osmesa.h>

#include <memory>
#include <mutex>
#include <string>

#include "client/viewer/framebuffer.h"

namespace meshstream::client {
namespace {

void* osmesa_proc(const char* name) { return reinterpret_cast<void*>(OSMesaGetProcAddress(name)); }

struct ContextDeleter {
  void operator()(osmesa_context* context) const { OSMesaDestroyContext(context); }
};

}  // namespace

Result<RgbaImage> render_offscreen(const Mesh& mesh, const OffscreenRequest& request) {
  if (request.width < 1 || request.height < 1 || request.width > 8192 || request.height > 8192) {
    return make_error(ErrorCode::kInvalidArgument,
                      "snapshot size " + std::to_string(request.width) + "x" +
                          std::to_string(request.height) + " is outside 1..8192");
  }
  if (Status valid = validate_arrays(mesh); !valid) {
    return tl::unexpected(std::move(valid.error()).with_context("snapshot mesh"));
  }

  static std::mutex one_context_at_a_time;
  std::lock_guard lock(one_context_at_a_time);

  const int attributes[] = {OSMESA_FORMAT,
                            OSMESA_RGBA,
                            OSMESA_DEPTH_BITS,
                            24,
                            OSMESA_PROFILE,
                            OSMESA_CORE_PROFILE,
                            OSMESA_CONTEXT_MAJOR_VERSION,
                            3,
                            OSMESA_CONTEXT_MINOR_VERSION,
                            3,
                            0};
  std::unique_ptr<osmesa_context, ContextDeleter> context(
      OSMesaCreateContextAttribs(attributes, nullptr));
  if (!context) {
    return make_error(ErrorCode::kUnsupported, "OSMesa cannot create an OpenGL 3.3 core context");
  }
  // The context's own framebuffer is only a placeholder: drawing goes to a
  // multisampled framebuffer object of the requested size.
  std::vector<uint8_t> placeholder(16 * 16 * 4);
  if (!OSMesaMakeCurrent(context.get(), placeholder.data(), GL_UNSIGNED_BYTE, 16, 16)) {
    return make_error(ErrorCode::kUnsupported, "OSMesa cannot make its context current");
  }
  struct ReleaseCurrent {
    ~ReleaseCurrent() { OSMesaMakeCurrent(nullptr, nullptr, GL_UNSIGNED_BYTE, 0, 0); }
  } release_current;

  auto gl = load_gl_functions(&osmesa_proc);
  if (!gl) return tl::unexpected(gl.error());
  Result<RgbaImage> image = [&]() -> Result<RgbaImage> {
    auto target = OffscreenFramebuffer::create(*gl, request.width, request.height, request.samples);
    if (!target) return tl::unexpected(target.error());
    auto renderer = MeshRenderer::create(*gl);
    if (!renderer) return tl::unexpected(renderer.error());
    renderer->upload(mesh, request.face_kind, request.crease_degrees);
    if (request.vertex_distance != nullptr) renderer->upload_distances(*request.vertex_distance);

    OrbitCamera camera;
    camera.yaw = request.yaw;
    camera.pitch = request.pitch;
    float aspect = static_cast<float>(request.width) / static_cast<float>(request.height);
    if (request.camera)
      camera.look_from(*request.camera, request.frame_on ? *request.frame_on : mesh);
    else
      camera.frame(request.frame_on ? *request.frame_on : mesh, aspect, request.fill);

    target->bind_for_drawing();
    renderer->draw(camera, request.width, request.height, request.style);
    gl->Finish();
    return target->read();
  }();
  return image;
}

}  // namespace meshstream::client
