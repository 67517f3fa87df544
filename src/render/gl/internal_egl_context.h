#pragma once
// A headless OpenGL 3.3+ core context through EGL, with no surface and no display server.
//
// Which EGL display (first that gives a context wins):
//   1. an EGL device (EGL_EXT_device_enumeration + EGL_EXT_platform_device) that is a real GPU:
//      NVIDIA's (EGL_NV_device_cuda) first, then any other non-software device (a DRM node);
//   2. Mesa's surfaceless platform (EGL_MESA_platform_surfaceless): llvmpipe without a GPU;
//   3. Mesa's software EGL device (EGL_MESA_device_software);
//   4. eglGetDisplay(EGL_DEFAULT_DISPLAY) (old vendor drivers that are headless there).
// The environment variable SACCADE_EGL_DEVICE overrides the choice: "surfaceless" for 2, or
// the index of an EGL device (as eglQueryDevicesEXT lists them).
//
// The context is made current with EGL_NO_SURFACE (EGL_KHR_surfaceless_context); rendering
// goes to framebuffer objects. GL and EGL entry points come from libepoxy.

#include <string>

namespace saccade::render::gl {

/// The name of an EGL error code: "EGL_BAD_ALLOC", ... ("0x3003" style when unknown).
std::string EglErrorName(int code);

/// Owns one EGL context on a (process-wide, reference-counted) EGL display. Not copyable.
/// Not thread-safe: one thread uses it at a time.
class EglContext {
 public:
  /// Opens a display and makes a 3.3+ core context current on the calling thread. Throws
  /// saccade::Error naming the EGL call and error code of every display tried when none works.
  EglContext();
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  /// Makes the context current on this thread (a cheap check when it already is). Throws
  /// saccade::Error when EGL refuses.
  void MakeCurrent();
  /// Which EGL display was chosen, e.g. "EGL device 0 (EGL_NV_device_cuda)", "surfaceless Mesa".
  const std::string& display_name() const { return display_name_; }

 private:
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
  std::string display_name_;
};

}  // namespace saccade::render::gl
