#include "saccade/render/renderer.h"

#include <fmt/format.h>

#include <cmath>
#include <set>

#include "render/gl/internal_gl_renderer.h"
#include "saccade/core/error.h"

namespace saccade::render {

bool RendererOptions::IsValid(std::string* error) const {
  std::string message;
  if (msaa_samples != 0 && msaa_samples != 2 && msaa_samples != 4 && msaa_samples != 8) {
    message = fmt::format("msaa_samples must be 0 (off), 2, 4 or 8, got {}", msaa_samples);
  } else if (!std::isfinite(lod_max_error_px) || lod_max_error_px < 0.0) {
    message =
        fmt::format("lod_max_error_px must be finite and >= 0 (0: full detail always), got {}",
                    lod_max_error_px);
  } else if (!std::isfinite(turn_blur_max_error_px) || turn_blur_max_error_px < 0.0) {
    message = fmt::format("turn_blur_max_error_px must be finite and >= 0, got {}",
                          turn_blur_max_error_px);
  } else if (batch_contexts < 0 || batch_contexts > 2) {
    message = fmt::format("batch_contexts must be 0 (automatic), 1 or 2, got {}", batch_contexts);
  } else {
    std::set<std::string> seen;
    for (const std::string& name : cameras) {
      if (name.empty()) {
        message = "cameras: a camera name is empty";
        break;
      }
      if (!seen.insert(name).second) {
        message = fmt::format("cameras: camera \"{}\" is listed twice", name);
        break;
      }
    }
  }
  if (error != nullptr) *error = message;
  return message.empty();
}

void Renderer::RenderBatch(const std::vector<BatchHead>& /*heads*/, uint8_t* /*out*/,
                           std::size_t /*out_bytes*/) {
  throw Error("Renderer::RenderBatch: this renderer has no batch path");
}

std::unique_ptr<Renderer> MakeRenderer(const scene::Scene& scene, const RendererOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) {
    throw InvalidArgument("MakeRenderer: RendererOptions." + error);
  }
  std::vector<const scene::CameraSpec*> cameras;
  if (options.cameras.empty()) {
    for (const scene::CameraSpec& camera : scene.cameras()) cameras.push_back(&camera);
    if (cameras.empty()) {
      throw InvalidArgument("MakeRenderer: the scene has no cameras; expected at least one");
    }
  } else {
    for (const std::string& name : options.cameras) {
      const scene::CameraSpec* camera = scene.FindCamera(name);
      if (camera == nullptr) {
        std::string known;
        for (const scene::CameraSpec& c : scene.cameras()) {
          known += (known.empty() ? "" : ", ") + ("\"" + c.name + "\"");
        }
        throw InvalidArgument(fmt::format(
            "MakeRenderer: RendererOptions.cameras: unknown camera \"{}\"; the scene has {}", name,
            known.empty() ? std::string("no cameras") : known));
      }
      cameras.push_back(camera);
    }
  }
  std::vector<std::string> names;
  for (const scene::CameraSpec* camera : cameras) names.push_back(camera->name);
  return gl::MakeGlRenderer(scene, options, names);
}

}  // namespace saccade::render
