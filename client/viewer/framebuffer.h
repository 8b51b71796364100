// A multisampled off-screen colour + depth target that resolves into a
// single-sampled one for reading back: anti-aliased snapshots on any
// context, including OSMesa whose own framebuffer has no multisampling.
#pragma once

#include "client/viewer/gl_functions.h"
#include "client/viewer/rgba_image.h"
#include "common/base/result.h"

namespace meshstream::client {

class OffscreenFramebuffer {
 public:
  // `samples` is clamped to what the context offers (1: no multisampling).
  // kUnsupported when the framebuffer is incomplete; kInvalidArgument for a
  // size outside 1..GL_MAX_RENDERBUFFER_SIZE.
  static Result<OffscreenFramebuffer> create(const GlFunctions& gl, int width, int height,
                                             int samples);
  OffscreenFramebuffer() = default;
  OffscreenFramebuffer(OffscreenFramebuffer&& other) noexcept;
  OffscreenFramebuffer& operator=(OffscreenFramebuffer&& other) noexcept;
  ~OffscreenFramebuffer();

  void bind_for_drawing() const;
  // Resolves the samples and reads the pixels back, top row first. O(pixels).
  RgbaImage read() const;

 private:
  void release();
  GlFunctions gl_{};
  bool created_ = false;
  int width_ = 0, height_ = 0;
  GLuint draw_fbo_ = 0, resolve_fbo_ = 0;
  GLuint color_rb_ = 0, depth_rb_ = 0, resolve_rb_ = 0;
};

}  // namespace meshstream::client
