#include "render/gl/internal_egl_context.h"

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <fmt/format.h>

#include <cstdlib>
#include <map>
#include <mutex>
#include <string_view>
#include <vector>

#include "saccade/core/error.h"

namespace saccade::render::gl {
namespace {

// EGL displays are process-wide: eglInitialize on an initialised display is a no-op and
// eglTerminate ends it for everyone, so displays are reference-counted by the contexts on them.
std::mutex display_mutex;
std::map<EGLDisplay, int>& DisplayUsers() {
  static std::map<EGLDisplay, int> users;
  return users;
}

void ReleaseDisplay(EGLDisplay display, bool was_counted) {
  std::lock_guard<std::mutex> lock(display_mutex);
  int& users = DisplayUsers()[display];
  if (was_counted) --users;
  if (users <= 0) {
    DisplayUsers().erase(display);
    eglTerminate(display);
  }
}

bool HasExtension(const char* list, std::string_view name) {
  if (list == nullptr) return false;
  std::string_view all(list);
  for (std::size_t pos = 0; pos < all.size();) {
    std::size_t end = all.find(' ', pos);
    if (end == std::string_view::npos) end = all.size();
    if (all.substr(pos, end - pos) == name) return true;
    pos = end + 1;
  }
  return false;
}

bool HasClientExtension(std::string_view name) {
  return HasExtension(eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS), name);
}

// A display to try and what to call it in messages.
struct Candidate {
  std::string name;
  EGLenum platform = 0;  // 0: eglGetDisplay(EGL_DEFAULT_DISPLAY)
  void* native = nullptr;
};

std::string LastError(const char* call) {
  return fmt::format("{} failed: {}", call, EglErrorName(eglGetError()));
}

// Initialises `display` and creates a 3.3+ core context on it, current on this thread. On
// failure returns an empty context and says why in *error (the display is left initialised:
// the caller releases it).
EGLContext CreateContext(EGLDisplay display, std::string* error) {
  EGLint major = 0, minor = 0;
  if (eglInitialize(display, &major, &minor) != EGL_TRUE) {
    *error = LastError("eglInitialize");
    return EGL_NO_CONTEXT;
  }
  if (major < 1 || (major == 1 && minor < 4)) {
    *error = fmt::format("EGL {}.{} is too old, expected 1.4 or later", major, minor);
    return EGL_NO_CONTEXT;
  }
  if (!HasExtension(eglQueryString(display, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context")) {
    *error = "EGL_KHR_surfaceless_context is missing (needed to render without a surface)";
    return EGL_NO_CONTEXT;
  }
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) {
    *error = LastError("eglBindAPI(EGL_OPENGL_API)");
    return EGL_NO_CONTEXT;
  }
  EGLConfig config = EGL_NO_CONFIG_KHR;
  if (!HasExtension(eglQueryString(display, EGL_EXTENSIONS), "EGL_KHR_no_config_context")) {
    const EGLint config_attributes[] = {EGL_SURFACE_TYPE,
                                        EGL_PBUFFER_BIT,
                                        EGL_RENDERABLE_TYPE,
                                        EGL_OPENGL_BIT,
                                        EGL_RED_SIZE,
                                        8,
                                        EGL_GREEN_SIZE,
                                        8,
                                        EGL_BLUE_SIZE,
                                        8,
                                        EGL_NONE};
    EGLint count = 0;
    if (eglChooseConfig(display, config_attributes, &config, 1, &count) != EGL_TRUE) {
      *error = LastError("eglChooseConfig");
      return EGL_NO_CONTEXT;
    }
    if (count < 1) {
      *error = "eglChooseConfig found no config with EGL_OPENGL_BIT";
      return EGL_NO_CONTEXT;
    }
  }
  const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                       3,
                                       EGL_CONTEXT_MINOR_VERSION,
                                       3,
                                       EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                       EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                       EGL_NONE};
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attributes);
  if (context == EGL_NO_CONTEXT) {
    *error = LastError("eglCreateContext(OpenGL 3.3 core)");
    return EGL_NO_CONTEXT;
  }
  if (eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context) != EGL_TRUE) {
    *error = LastError("eglMakeCurrent(EGL_NO_SURFACE)");
    eglDestroyContext(display, context);
    return EGL_NO_CONTEXT;
  }
  const int version = epoxy_gl_version();
  if (version < 33) {
    *error = fmt::format("the context is OpenGL {}.{}, expected 3.3 or later", version / 10,
                         version % 10);
    eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display, context);
    return EGL_NO_CONTEXT;
  }
  return context;
}

std::vector<Candidate> Candidates() {
  std::vector<Candidate> devices_gpu, devices_software, out;
  std::vector<EGLDeviceEXT> devices;
  if (HasClientExtension("EGL_EXT_device_enumeration") &&
      HasClientExtension("EGL_EXT_platform_device")) {
    EGLint count = 0;
    if (eglQueryDevicesEXT(0, nullptr, &count) == EGL_TRUE && count > 0) {
      devices.resize(static_cast<std::size_t>(count));
      if (eglQueryDevicesEXT(count, devices.data(), &count) != EGL_TRUE) count = 0;
      devices.resize(static_cast<std::size_t>(count));
    }
  }
  const bool surfaceless = HasClientExtension("EGL_MESA_platform_surfaceless");

  // The override (SACCADE_EGL_DEVICE): a device index or "surfaceless".
  if (const char* choice = std::getenv("SACCADE_EGL_DEVICE"); choice != nullptr && *choice) {
    const std::string value(choice);
    if (value == "surfaceless") {
      if (!surfaceless) {
        throw Error("SACCADE_EGL_DEVICE=surfaceless: EGL has no EGL_MESA_platform_surfaceless");
      }
      return {{"surfaceless Mesa", EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY}};
    }
    char* end = nullptr;
    const long index = std::strtol(value.c_str(), &end, 10);
    if (end == value.c_str() || *end != '\0' || index < 0 ||
        index >= static_cast<long>(devices.size())) {
      throw Error(fmt::format(
          "SACCADE_EGL_DEVICE must be \"surfaceless\" or an EGL device index in [0, {}), got "
          "\"{}\"",
          devices.size(), value));
    }
    return {{fmt::format("EGL device {}", index), EGL_PLATFORM_DEVICE_EXT,
             devices[static_cast<std::size_t>(index)]}};
  }

  std::vector<Candidate> nvidia;
  for (std::size_t i = 0; i < devices.size(); ++i) {
    const char* extensions = eglQueryDeviceStringEXT(devices[i], EGL_EXTENSIONS);
    Candidate candidate{fmt::format("EGL device {} ({})", i, extensions ? extensions : ""),
                        EGL_PLATFORM_DEVICE_EXT, devices[i]};
    if (HasExtension(extensions, "EGL_MESA_device_software")) {
      devices_software.push_back(candidate);
    } else if (HasExtension(extensions, "EGL_NV_device_cuda")) {
      nvidia.push_back(candidate);
    } else {
      devices_gpu.push_back(candidate);
    }
  }
  out = nvidia;
  out.insert(out.end(), devices_gpu.begin(), devices_gpu.end());
  if (surfaceless) {
    out.push_back({"surfaceless Mesa", EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY});
  }
  out.insert(out.end(), devices_software.begin(), devices_software.end());
  out.push_back({"eglGetDisplay(EGL_DEFAULT_DISPLAY)", 0, nullptr});
  return out;
}

}  // namespace

std::string EglErrorName(int code) {
  switch (code) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_CURRENT_SURFACE:
      return "EGL_BAD_CURRENT_SURFACE";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_NATIVE_PIXMAP:
      return "EGL_BAD_NATIVE_PIXMAP";
    case EGL_BAD_NATIVE_WINDOW:
      return "EGL_BAD_NATIVE_WINDOW";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE:
      return "EGL_BAD_SURFACE";
    case EGL_CONTEXT_LOST:
      return "EGL_CONTEXT_LOST";
    default:
      return fmt::format("EGL error 0x{:04X}", code);
  }
}

EglContext::EglContext() {
  std::string failures;
  for (const Candidate& candidate : Candidates()) {
    EGLDisplay display =
        candidate.platform == 0
            ? eglGetDisplay(EGL_DEFAULT_DISPLAY)
            : eglGetPlatformDisplayEXT(candidate.platform, candidate.native, nullptr);
    std::string error;
    EGLContext context = EGL_NO_CONTEXT;
    if (display == EGL_NO_DISPLAY) {
      error = LastError(candidate.platform == 0 ? "eglGetDisplay" : "eglGetPlatformDisplayEXT");
    } else {
      std::lock_guard<std::mutex> lock(display_mutex);
      context = CreateContext(display, &error);
      if (context != EGL_NO_CONTEXT) ++DisplayUsers()[display];
    }
    if (context != EGL_NO_CONTEXT) {
      display_ = display;
      context_ = context;
      display_name_ = candidate.name;
      return;
    }
    if (display != EGL_NO_DISPLAY) ReleaseDisplay(display, /*was_counted=*/false);
    failures += fmt::format("\n  {}: {}", candidate.name, error);
  }
  throw Error(
      "MakeRenderer: no OpenGL 3.3 core context could be made through EGL (headless); tried:" +
      failures);
}

EglContext::~EglContext() {
  if (context_ == nullptr) return;
  if (eglGetCurrentContext() == context_) {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
  eglDestroyContext(display_, context_);
  ReleaseDisplay(display_, /*was_counted=*/true);
}

void EglContext::MakeCurrent() {
  if (eglGetCurrentContext() == context_) return;
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE ||
      eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) != EGL_TRUE) {
    throw Error(fmt::format("Renderer: {} ({})", LastError("eglMakeCurrent"), display_name_));
  }
}

}  // namespace saccade::render::gl
