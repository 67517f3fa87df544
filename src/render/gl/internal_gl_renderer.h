#pragma once
// The OpenGL backend of render::Renderer (renderer.h): EGL context (internal_egl_context.h),
// models and textures uploaded once (internal_gpu_resources.h), one framebuffer and two pixel
// buffers per camera (internal_camera_target.h), the shaders of internal_shaders.h.
//
// Per state, Submit computes every pose in double precision on the CPU (model-view =
// OpticalToGlEye * X_WC^-1 * X_WO * scale, then cast to float, so that sub-pixel accuracy
// holds metres from the origin), draws every camera (objects front to back, culled against
// the frustum, then the ground), then starts the readback of every camera into the slot's
// pixel buffers and sets a fence; drawing all cameras before reading any lets the device (or
// llvmpipe's rasteriser threads) work on one camera while the next is submitted. Retrieve
// waits on the oldest fence, maps the pixel buffers and converts RGBA to a kRgb8 Image with
// its metadata (images are recycled once the caller has let go of them).
//
// On a GPU the copy into the pixel buffers runs behind the draws and Submit returns at once.
// On llvmpipe glReadPixels is a CPU copy that first waits for the rasteriser threads, so
// Submit returns with the pixels in the buffers. (Deferring that copy to Retrieve, from a
// framebuffer per slot and even through a second shared context, was measured to gain nothing
// on Mesa 22.3: mapping the framebuffer waits for all queued rendering, the next state's
// included.)

#include <memory>
#include <string>
#include <vector>

#include "saccade/render/renderer.h"

namespace saccade::render::gl {

/// The OpenGL renderer for the named cameras of `scene` (names already checked to exist).
/// Throws saccade::Error when no context can be made or the device refuses a resource.
std::unique_ptr<Renderer> MakeGlRenderer(const scene::Scene& scene, const RendererOptions& options,
                                         const std::vector<std::string>& camera_names);

}  // namespace saccade::render::gl
