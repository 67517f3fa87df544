#pragma once
// One camera's render target: a framebuffer at exactly the camera's size (no power-of-two
// padding) with an RGBA8 colour and a 32-bit float depth attachment, multisampled when MSAA
// is on (then resolved into a single-sample framebuffer by glBlitFramebuffer), and two pixel
// buffer objects (one per in-flight slot) that receive the pixels asynchronously.
//
// Rows: the projection flips them (flip_rows = true), so framebuffer row 0 is the image's top
// row and glReadPixels, which starts at row 0, writes the image top row first.

#include <epoxy/gl.h>

#include <cstdint>

namespace saccade::render::gl {

class CameraTarget {
 public:
  /// States in flight at once: pixel buffers per camera.
  static constexpr int kSlots = 2;

  /// `samples` 0 for no MSAA; `readback_format` GL_RGBA (4 bytes a pixel) or GL_RGB (3,
  /// GL_PACK_ALIGNMENT 1). Throws saccade::Error naming the size when the framebuffer is
  /// incomplete or the device refuses it. Needs the context current.
  CameraTarget(int width, int height, int samples, GLenum readback_format);
  ~CameraTarget();
  CameraTarget(const CameraTarget&) = delete;
  CameraTarget& operator=(const CameraTarget&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }
  /// Bytes of one row in the pixel buffers.
  int row_bytes() const { return width_ * bytes_per_pixel_; }

  /// Binds the framebuffer to draw into and sets the viewport.
  void BindForDrawing() const;
  /// Resolves MSAA if any and starts the copy of the pixels into the slot's pixel buffer.
  void StartReadback(int slot) const;
  /// Maps the slot's pixel buffer for reading (after its fence), nullptr on failure; Unmap
  /// after use.
  const uint8_t* Map(int slot) const;
  void Unmap() const;

 private:
  int width_;
  int height_;
  int samples_;
  GLenum readback_format_;
  int bytes_per_pixel_;
  GLuint draw_framebuffer_ = 0;
  GLuint resolve_framebuffer_ = 0;  // == draw_framebuffer_ without MSAA
  GLuint color_ = 0;
  GLuint depth_ = 0;
  GLuint resolve_color_ = 0;
  GLuint pixel_buffers_[kSlots] = {0, 0};
};

}  // namespace saccade::render::gl
