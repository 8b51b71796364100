#include "client/viewer/framebuffer.h"

#include <algorithm>
#include <string>
#include <utility>

namespace meshstream::client {

Result<OffscreenFramebuffer> OffscreenFramebuffer::create(const GlFunctions& gl, int width,
                                                          int height, int samples) {
  GLint max_size = 0, max_samples = 0;
  gl.GetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_size);
  gl.GetIntegerv(GL_MAX_SAMPLES, &max_samples);
  if (width < 1 || height < 1 || width > max_size || height > max_size) {
    return make_error(ErrorCode::kInvalidArgument, "snapshot size " + std::to_string(width) + "x" +
                                                       std::to_string(height) + " is outside 1.." +
                                                       std::to_string(max_size));
  }
  samples = std::clamp(samples, 1, std::max(1, static_cast<int>(max_samples)));
  OffscreenFramebuffer fb;
  fb.gl_ = gl;
  fb.width_ = width;
  fb.height_ = height;
  fb.created_ = true;
  GLuint rbs[3];
  gl.GenRenderbuffers(3, rbs);
  fb.color_rb_ = rbs[0];
  fb.depth_rb_ = rbs[1];
  fb.resolve_rb_ = rbs[2];
  GLuint fbos[2];
  gl.GenFramebuffers(2, fbos);
  fb.draw_fbo_ = fbos[0];
  fb.resolve_fbo_ = fbos[1];

  gl.BindRenderbuffer(GL_RENDERBUFFER, fb.color_rb_);
  gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, width, height);
  gl.BindRenderbuffer(GL_RENDERBUFFER, fb.depth_rb_);
  gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, width, height);
  gl.BindRenderbuffer(GL_RENDERBUFFER, fb.resolve_rb_);
  gl.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  gl.BindRenderbuffer(GL_RENDERBUFFER, 0);

  gl.BindFramebuffer(GL_FRAMEBUFFER, fb.draw_fbo_);
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, fb.color_rb_);
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, fb.depth_rb_);
  GLenum draw_status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
  gl.BindFramebuffer(GL_FRAMEBUFFER, fb.resolve_fbo_);
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, fb.resolve_rb_);
  GLenum resolve_status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  if (draw_status != GL_FRAMEBUFFER_COMPLETE || resolve_status != GL_FRAMEBUFFER_COMPLETE) {
    return make_error(ErrorCode::kUnsupported, "off-screen framebuffer is incomplete (status " +
                                                   std::to_string(draw_status) + ", " +
                                                   std::to_string(resolve_status) + ")");
  }
  return fb;
}

OffscreenFramebuffer::OffscreenFramebuffer(OffscreenFramebuffer&& other) noexcept {
  *this = std::move(other);
}

OffscreenFramebuffer& OffscreenFramebuffer::operator=(OffscreenFramebuffer&& other) noexcept {
  if (this != &other) {
    release();
    gl_ = other.gl_;
    created_ = std::exchange(other.created_, false);
    width_ = other.width_;
    height_ = other.height_;
    draw_fbo_ = other.draw_fbo_;
    resolve_fbo_ = other.resolve_fbo_;
    color_rb_ = other.color_rb_;
    depth_rb_ = other.depth_rb_;
    resolve_rb_ = other.resolve_rb_;
  }
  return *this;
}

OffscreenFramebuffer::~OffscreenFramebuffer() { release(); }

void OffscreenFramebuffer::release() {
  if (!created_) return;
  created_ = false;
  GLuint fbos[2] = {draw_fbo_, resolve_fbo_};
  gl_.DeleteFramebuffers(2, fbos);
  GLuint rbs[3] = {color_rb_, depth_rb_, resolve_rb_};
  gl_.DeleteRenderbuffers(3, rbs);
}

void OffscreenFramebuffer::bind_for_drawing() const {
  gl_.BindFramebuffer(GL_FRAMEBUFFER, draw_fbo_);
}

RgbaImage OffscreenFramebuffer::read() const {
  gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, draw_fbo_);
  gl_.BindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo_);
  gl_.BlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT,
                      GL_NEAREST);
  gl_.BindFramebuffer(GL_FRAMEBUFFER, resolve_fbo_);
  gl_.ReadBuffer(GL_COLOR_ATTACHMENT0);
  gl_.PixelStorei(GL_PACK_ALIGNMENT, 1);
  RgbaImage image;
  image.width = width_;
  image.height = height_;
  image.rgba.resize(static_cast<size_t>(width_) * height_ * 4);
  gl_.ReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, image.rgba.data());
  gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
  flip_rows(image);
  return image;
}

}  // namespace meshstream::client
