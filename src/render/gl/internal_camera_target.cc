#include "render/gl/internal_camera_target.h"

#include <fmt/format.h>

#include "render/gl/internal_gl_util.h"
#include "saccade/core/error.h"

namespace saccade::render::gl {
namespace {

void CheckTargetComplete(int width, int height, int samples) {
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    throw Error(
        fmt::format("Renderer: the {} x {} framebuffer ({} samples) is incomplete: status 0x{:04X}",
                    width, height, samples, status));
  }
}

}  // namespace

CameraTarget::CameraTarget(int width, int height, int samples, GLenum readback_format)
    : width_(width),
      height_(height),
      samples_(samples),
      readback_format_(readback_format),
      bytes_per_pixel_(readback_format == GL_RGB ? 3 : 4) {
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_size);
  if (width < 1 || height < 1 || width > max_size || height > max_size) {
    throw Error(fmt::format(
        "Renderer: a camera image of {} x {} pixels is beyond the device's limit of {} a side",
        width, height, max_size));
  }
  color_ = MakeRenderbuffer(GL_RGBA8, width, height, samples);
  depth_ = MakeRenderbuffer(GL_DEPTH_COMPONENT32F, width, height, samples);
  glGenFramebuffers(1, &draw_framebuffer_);
  glBindFramebuffer(GL_FRAMEBUFFER, draw_framebuffer_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
  CheckTargetComplete(width, height, samples);
  if (samples > 0) {
    resolve_color_ = MakeRenderbuffer(GL_RGBA8, width, height, 0);
    glGenFramebuffers(1, &resolve_framebuffer_);
    glBindFramebuffer(GL_FRAMEBUFFER, resolve_framebuffer_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                              resolve_color_);
    CheckTargetComplete(width, height, 0);
  } else {
    resolve_framebuffer_ = draw_framebuffer_;
  }
  glGenBuffers(kSlots, pixel_buffers_);
  for (GLuint buffer : pixel_buffers_) {
    glBindBuffer(GL_PIXEL_PACK_BUFFER, buffer);
    glBufferData(GL_PIXEL_PACK_BUFFER, static_cast<GLsizeiptr>(row_bytes()) * height, nullptr,
                 GL_STREAM_READ);
  }
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glBindRenderbuffer(GL_RENDERBUFFER, 0);
  CheckGlError(
      fmt::format("Renderer: making a {} x {} framebuffer ({} samples)", width, height, samples));
}

CameraTarget::~CameraTarget() {
  glDeleteBuffers(kSlots, pixel_buffers_);
  if (resolve_framebuffer_ != draw_framebuffer_) glDeleteFramebuffers(1, &resolve_framebuffer_);
  glDeleteFramebuffers(1, &draw_framebuffer_);
  const GLuint renderbuffers[] = {color_, depth_, resolve_color_};
  glDeleteRenderbuffers(3, renderbuffers);
}

void CameraTarget::BindForDrawing() const {
  glBindFramebuffer(GL_FRAMEBUFFER, draw_framebuffer_);
  glViewport(0, 0, width_, height_);
}

void CameraTarget::StartReadback(int slot) const {
  if (samples_ > 0) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_framebuffer_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_framebuffer_);
    glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT,
                      GL_NEAREST);
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_framebuffer_);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, pixel_buffers_[slot]);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, readback_format_, GL_UNSIGNED_BYTE, nullptr);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
}

const uint8_t* CameraTarget::Map(int slot) const {
  glBindBuffer(GL_PIXEL_PACK_BUFFER, pixel_buffers_[slot]);
  return static_cast<const uint8_t*>(glMapBufferRange(
      GL_PIXEL_PACK_BUFFER, 0, static_cast<GLsizeiptr>(row_bytes()) * height_, GL_MAP_READ_BIT));
}

void CameraTarget::Unmap() const {
  glUnmapBuffer(GL_PIXEL_PACK_BUFFER);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
}

}  // namespace saccade::render::gl
