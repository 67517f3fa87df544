// Ground truth of a frame: depth and instance ids read back, and each object's (and the
// robot's) pose, pixel count and box in the image; the depth of field's depth from the colour
// pass where that stands for the truth pass (internal_color_depth.h).
#include <algorithm>
#include <cstring>
#include <map>
#include <vector>

#include "render/gl/internal_cpu_lens.h"
#include "render/gl/internal_gl_renderer_impl.h"
#include "render/gl/internal_pixels.h"
#include "saccade/core/error.h"

namespace saccade::render::gl {

void GlRenderer::FillTruth(int camera, const Pending& pending, int slot, Frame* frame,
                           std::shared_ptr<Image>* depth) {
  const EffectTarget& effects = *setups_[camera].effects;
  const int width = frame->color->width();
  const int height = frame->color->height();
  const std::size_t bytes = static_cast<std::size_t>(width) * height * 4;
  const auto copy = [&](const PixelBuffers& buffers, PixelFormat format) {
    auto image = std::make_shared<Image>(width, height, format);
    image->metadata() = frame->color->metadata();
    const uint8_t* mapped = MapOrThrow(buffers, slot, " (truth)");
    // In chunks of rows on every core (rows packed both sides).
    const std::size_t row = image->stride();
    InRowChunks(height, bytes / 4, [&](int first, int end) {
      std::memcpy(image->row(first), mapped + row * first, row * (end - first));
    });
    buffers.Unmap();
    return image;
  };
  if (options_.truth_depth || depth != nullptr) {
    std::shared_ptr<Image> z = copy(effects.depth_buffers(), PixelFormat::kFloat32);
    if (options_.truth_depth) frame->depth = z;
    if (depth != nullptr) *depth = std::move(z);
  }
  if (!options_.truth_ids && !options_.truth_objects) return;
  std::shared_ptr<Image> ids = copy(effects.id_buffers(), PixelFormat::kUint32);
  frame->ids = ids;
  if (!options_.truth_objects) return;

  // Poses at the frame's time, and boxes from the id image.
  const geometry::Pose X_CW = pending.X_WC[camera].inverse();
  std::map<uint32_t, std::size_t> index;  // id -> entry
  for (const scene::Object& object : scene_.objects()) {
    ObjectTruth truth;
    truth.id = object.id;
    truth.name = object.name;
    const geometry::Pose X_WO = scene_.ObjectPose(object, pending.state);
    truth.X_WO = X_WO.matrix();
    truth.X_CO = (X_CW * X_WO).matrix();
    index.emplace(truth.id, frame->objects.size());
    frame->objects.push_back(truth);
  }
  if (draw_robot_) {
    ObjectTruth truth;
    truth.id = scene_.robot()->id;
    truth.name = "robot";
    const geometry::Pose X_WB = scene_.robot()->head.X_WB();
    truth.X_WO = X_WB.matrix();
    truth.X_CO = (X_CW * X_WB).matrix();
    index.emplace(truth.id, frame->objects.size());
    frame->objects.push_back(truth);
  }
  uint32_t last_id = 0;
  ObjectTruth* last = nullptr;
  for (int y = 0; y < height; ++y) {
    const auto* row = reinterpret_cast<const uint32_t*>(ids->row(y));
    for (int x = 0; x < width; ++x) {
      const uint32_t id = row[x];
      if (id == 0) continue;
      if (id != last_id || last == nullptr) {
        const auto found = index.find(id);
        if (found == index.end()) continue;  // cannot happen: every drawn id is listed
        last_id = id;
        last = &frame->objects[found->second];
      }
      if (last->pixels == 0) {
        last->x_min = last->x_max = x;
        last->y_min = last->y_max = y;
      }
      ++last->pixels;
      last->x_min = std::min(last->x_min, x);
      last->x_max = std::max(last->x_max, x);
      last->y_min = std::min(last->y_min, y);
      last->y_max = std::max(last->y_max, y);
    }
  }
}

std::shared_ptr<Image> GlRenderer::ColorPassDepth(int camera, int slot, const Image& color) {
  CameraSetup& setup = setups_[camera];
  const EffectTarget& effects = *setup.effects;
  const PixelBuffers& buffers = effects.color_depth_buffers();
  const auto* window_depth =
      reinterpret_cast<const float*>(MapOrThrow(buffers, slot, " (colour depth)"));
  auto depth = std::make_shared<Image>(color.width(), color.height(), PixelFormat::kFloat32);
  depth->metadata() = color.metadata();
  const CpuLens* lens = effects.cpu_lens();
  // An identity lens: the source is the camera, its z the depth; else the source's z (into the
  // setup's buffer, kept from frame to frame), remapped.
  const std::size_t source_pixels = static_cast<std::size_t>(buffers.width()) * buffers.height();
  if (lens != nullptr) setup.color_depth_source_z.resize(source_pixels);
  float* z =
      lens != nullptr ? setup.color_depth_source_z.data() : reinterpret_cast<float*>(depth->data());
  InRowChunks(buffers.height(), source_pixels, [&](int first, int end) {
    CameraZRows(setup.color_depth, window_depth, first, end, z);
  });
  buffers.Unmap();
  if (lens != nullptr) {
    InRowChunks(depth->height(), source_pixels, [&](int first, int end) {
      for (int y = first; y < end; ++y) {
        lens->RemapDepthRow(z, y, reinterpret_cast<float*>(depth->row(y)));
      }
    });
  }
  return depth;
}

}  // namespace saccade::render::gl
