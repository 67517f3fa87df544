// Batch rendering (Renderer::RenderBatch): N heads, each with its own state and its own
// placement of the scene's objects, drawn through every camera into one framebuffer and read
// back at once.
//
// Layout: tile k = head * cameras + camera is layer k of a colour texture array, drawn at the
// origin of its layer. Every tile has the same window coordinates as a batch of one head has,
// so a head's images are the same to the bit whatever its place in the batch: a tile drawn at
// an offset in one large framebuffer (as before) had window coordinates, and the rasteriser's
// interpolation from the framebuffer's origin, of other float rounding, and a few thousand
// pixels of a vector env's 64 x 64 images differed from the same seeds' single envs. The
// projection flips rows (flip_rows, as every camera pass), so glReadPixels of a layer gives its
// image with row 0 at the top: one glReadPixels per tile into one pixel buffer gives the
// caller's heads x cameras x height x width layout directly, and one map reads it all. The draw
// calls are the single renderer's (DrawScene); what a batch saves is the per-call overhead: one
// framebuffer, one synchronisation and one readback for every image of every head, which is
// what dominates small images on llvmpipe.
//
// Two contexts (RendererOptions::batch_contexts): the second half of the tiles is drawn by a
// second renderer of the same scene, on a thread of its own (its context current there for
// good), into the same layers of its own framebuffer, and read back into its part of the
// caller's buffer. On llvmpipe the thread that issues draw calls does the
// vertex work, triangle setup and binning, then waits while the rasteriser's threads draw
// the scene it binned: with two issuing threads, one bins while the other's scene is drawn.
#include <fmt/format.h>

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>

#include "render/gl/internal_gl_renderer_impl.h"
#include "render/gl/internal_pixels.h"
#include "saccade/geometry/gl_projection.h"

namespace saccade::render::gl {
namespace {

// Hidden objects are moved this far below the ground: outside every camera's far plane, so
// that frustum culling drops them before any draw call.
constexpr double kHiddenDepth = 1e6;

// The fewest pixels a batch must have for the second context to draw half of it: four
// 128 x 128 images.
constexpr std::size_t kMinSplitPixels = 4 * 128 * 128;

}  // namespace

// The helper's thread: makes its renderer (its context current there for good), then runs
// one job at a time until stopped.
class GlRenderer::BatchHelper {
 public:
  BatchHelper(const scene::Scene& scene, RendererOptions options,
              std::vector<std::string> camera_names) {
    options.batch_contexts = 1;
    thread_ = std::thread(
        [this, &scene, options = std::move(options), camera_names = std::move(camera_names)] {
          Run(scene, options, camera_names);
        });
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait(lock, [this] { return made_; });
    if (error_ != nullptr) {
      std::exception_ptr error = std::exchange(error_, nullptr);
      lock.unlock();
      thread_.join();
      std::rethrow_exception(error);
    }
  }
  BatchHelper(const BatchHelper&) = delete;
  BatchHelper& operator=(const BatchHelper&) = delete;
  ~BatchHelper() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

  void Start(std::function<void(GlRenderer&)> job) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_ = std::move(job);
      busy_ = true;
    }
    wake_.notify_all();
  }

  // Waits for the job; rethrows what it threw when asked to.
  void Wait(bool rethrow) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait(lock, [this] { return !busy_; });
    std::exception_ptr error = std::exchange(error_, nullptr);
    if (rethrow && error != nullptr) std::rethrow_exception(error);
  }

 private:
  void Run(const scene::Scene& scene, const RendererOptions& options,
           const std::vector<std::string>& camera_names) {
    std::unique_ptr<GlRenderer> renderer;
    try {
      renderer = std::make_unique<GlRenderer>(scene, options, camera_names);
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      error_ = std::current_exception();
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      made_ = true;
    }
    ready_.notify_all();
    if (renderer == nullptr) return;
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return busy_ || stop_; });
      if (stop_) break;
      std::function<void(GlRenderer&)> job = std::move(job_);
      lock.unlock();
      std::exception_ptr error;
      try {
        job(*renderer);
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      error_ = error;
      busy_ = false;
      ready_.notify_all();
    }
    lock.unlock();
    renderer.reset();  // on the thread its context is current on
  }

  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable wake_, ready_;
  std::function<void(GlRenderer&)> job_;
  bool made_ = false, busy_ = false, stop_ = false;
  std::exception_ptr error_;
};

void GlRenderer::RenderBatch(const std::vector<BatchHead>& heads, uint8_t* out,
                             std::size_t out_bytes) {
  const Clock::time_point start = Clock::now();
  const int width = cameras_[0]->model.intrinsics().width();
  const int height = cameras_[0]->model.intrinsics().height();
  for (const scene::CameraSpec* camera : cameras_) {
    const geometry::Intrinsics& K = camera->model.intrinsics();
    if (K.width() != width || K.height() != height) {
      throw InvalidArgument(fmt::format(
          "Renderer::RenderBatch: every camera must have the same size; \"{}\" is {} x {}, "
          "\"{}\" is {} x {}",
          cameras_[0]->name, width, height, camera->name, K.width(), K.height()));
    }
  }
  const std::size_t objects = scene_.objects().size();
  for (std::size_t h = 0; h < heads.size(); ++h) {
    const BatchHead& head = heads[h];
    if (!head.object_poses.empty() && head.object_poses.size() != objects) {
      throw InvalidArgument(fmt::format(
          "Renderer::RenderBatch: head {}: object_poses has {} entries; expected 0 or one per "
          "scene object ({})",
          h, head.object_poses.size(), objects));
    }
    if (!head.hidden.empty() && head.hidden.size() != objects) {
      throw InvalidArgument(fmt::format(
          "Renderer::RenderBatch: head {}: hidden has {} entries; expected 0 or one per scene "
          "object ({})",
          h, head.hidden.size(), objects));
    }
  }
  const std::size_t cameras = cameras_.size();
  const std::size_t tiles = heads.size() * cameras;
  const std::size_t tile_bytes = static_cast<std::size_t>(width) * height * 3;
  if (out_bytes != tiles * tile_bytes) {
    throw InvalidArgument(fmt::format(
        "Renderer::RenderBatch: the output holds {} bytes; expected {} heads x {} cameras x {} x "
        "{} x 3 = {}",
        out_bytes, heads.size(), cameras, height, width, tiles * tile_bytes));
  }
  if (tiles == 0) return;

  context_.MakeCurrent();
  // Small batches stay on one context: handing half of a stereo pair of 128 x 128 images to
  // the other thread cost more than it saved (FixationEnv's step: 0.16 ms on one context,
  // 0.18-0.25 split).
  const bool split =
      tiles >= 2 && tiles * static_cast<std::size_t>(width) * height >= kMinSplitPixels;
  if (split && batch_contexts_ == 2 && batch_helper_ == nullptr) {
    try {
      batch_helper_.reset(new BatchHelper(scene_, options_, camera_names_));
    } catch (const Error&) {
      if (options_.batch_contexts == 2) throw;
      batch_contexts_ = 1;  // automatic: one context, as before
    }
    context_.MakeCurrent();
  }
  if (split && batch_helper_ != nullptr) {
    // The second half of the tiles on the helper's context, the first half here.
    const std::size_t middle = tiles / 2;
    batch_helper_->Start([&heads, middle, tiles, out](GlRenderer& helper) {
      helper.DrawBatchTiles(heads, middle, tiles, out);
    });
    try {
      DrawBatchTiles(heads, 0, middle, out);
    } catch (...) {
      batch_helper_->Wait(/*rethrow=*/false);
      throw;
    }
    batch_helper_->Wait(/*rethrow=*/true);
  } else {
    DrawBatchTiles(heads, 0, tiles, out);
  }
  stats_.frames += static_cast<int64_t>(heads.size());
  stats_.total_ms += Milliseconds(start, Clock::now());
}

void GlRenderer::DrawBatchTiles(const std::vector<BatchHead>& heads, std::size_t first,
                                std::size_t last, uint8_t* out) {
  const Clock::time_point start = Clock::now();
  context_.MakeCurrent();
  const int width = cameras_[0]->model.intrinsics().width();
  const int height = cameras_[0]->model.intrinsics().height();
  const std::size_t cameras = cameras_.size();
  const std::size_t count = last - first;
  const std::size_t tile_rgba = static_cast<std::size_t>(width) * height * 4;
  const int layers = PrepareBatchTarget(count);

  glBindFramebuffer(GL_FRAMEBUFFER, batch_.framebuffer);
  glDisable(GL_SCISSOR_TEST);
  glViewport(0, 0, width, height);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  double pose_ms = 0.0, read_ms = 0.0;
  std::size_t posed = heads.size();  // the head whose poses item_poses_ holds
  for (std::size_t part = first; part < last; part += static_cast<std::size_t>(layers)) {
    const std::size_t part_end = std::min(last, part + static_cast<std::size_t>(layers));
    for (std::size_t tile = part; tile < part_end; ++tile) {
      const std::size_t h = tile / cameras;
      const std::size_t c = tile % cameras;
      const BatchHead& head = heads[h];
      if (h != posed) {
        const Clock::time_point pose_start = Clock::now();
        PoseBatchHead(head);
        posed = h;
        pose_ms += Milliseconds(pose_start, Clock::now());
      }
      glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, batch_.color, 0,
                                static_cast<GLint>(tile - part));
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      DrawScene(batch_views_[c], cameras_[c]->clip.near,
                scene_.CameraPose(*cameras_[c], head.state));
    }
    // The part's layers into the pixel buffer, each at its tile's place.
    const Clock::time_point read_start = Clock::now();
    glBindBuffer(GL_PIXEL_PACK_BUFFER, batch_.pixels);
    for (std::size_t tile = part; tile < part_end; ++tile) {
      glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, batch_.color, 0,
                                static_cast<GLint>(tile - part));
      glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE,
                   reinterpret_cast<void*>((tile - first) * tile_rgba));
    }
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    read_ms += Milliseconds(read_start, Clock::now());
  }
  const Clock::time_point drawn = Clock::now();
  ConvertBatchPixels(first, count, out);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  CheckGlError("Renderer::RenderBatch");
  const Clock::time_point end = Clock::now();

  stats_.scene_update_ms += pose_ms;
  stats_.draw_ms += Milliseconds(start, drawn) - pose_ms - read_ms;
  stats_.readback_ms += Milliseconds(drawn, end) + read_ms;
}

int GlRenderer::PrepareBatchTarget(std::size_t count) {
  const int width = cameras_[0]->model.intrinsics().width();
  const int height = cameras_[0]->model.intrinsics().height();
  const std::size_t tile_rgba = static_cast<std::size_t>(width) * height * 4;
  // A batch of more tiles than the device's layers is drawn in parts, each read back before
  // the next.
  GLint max_layers = 0;
  glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &max_layers);
  const int layers = static_cast<int>(std::min<std::size_t>(count, std::max(1, max_layers)));
  if (batch_.framebuffer == 0 || layers > batch_.layers || count * tile_rgba > batch_.pixel_bytes) {
    MakeBatchTarget(layers, count * tile_rgba);
  }
  if (batch_views_.empty()) {
    for (const scene::CameraSpec* camera : cameras_) {
      const geometry::Intrinsics& K = camera->model.intrinsics();
      ViewSetup view;
      view.projection = geometry::GlProjectionFromIntrinsics(K, camera->clip, /*flip_rows=*/true);
      view.focal = std::max(K.fx(), K.fy());
      batch_views_.push_back(view);
    }
  }
  return layers;
}

void GlRenderer::MakeBatchTarget(int layers, std::size_t pixel_bytes) {
  const int width = cameras_[0]->model.intrinsics().width();
  const int height = cameras_[0]->model.intrinsics().height();
  if (batch_.framebuffer != 0) {
    glDeleteFramebuffers(1, &batch_.framebuffer);
    glDeleteTextures(1, &batch_.color);
    glDeleteRenderbuffers(1, &batch_.depth);
    glDeleteBuffers(1, &batch_.pixels);
  }
  batch_.layers = std::max(layers, batch_.layers);
  glGenTextures(1, &batch_.color);
  glBindTexture(GL_TEXTURE_2D_ARRAY, batch_.color);
  glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_RGBA8, width, height, batch_.layers, 0, GL_RGBA,
               GL_UNSIGNED_BYTE, nullptr);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAX_LEVEL, 0);
  glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
  glGenRenderbuffers(1, &batch_.depth);
  glBindRenderbuffer(GL_RENDERBUFFER, batch_.depth);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
  glBindRenderbuffer(GL_RENDERBUFFER, 0);
  glGenFramebuffers(1, &batch_.framebuffer);
  glBindFramebuffer(GL_FRAMEBUFFER, batch_.framebuffer);
  glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, batch_.color, 0, 0);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, batch_.depth);
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    throw Error(fmt::format(
        "Renderer::RenderBatch: the framebuffer of {} layers of {} x {} is incomplete: status "
        "0x{:04X}",
        batch_.layers, width, height, status));
  }
  batch_.pixel_bytes = std::max(batch_.pixel_bytes, pixel_bytes);
  glGenBuffers(1, &batch_.pixels);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, batch_.pixels);
  glBufferData(GL_PIXEL_PACK_BUFFER, static_cast<GLsizeiptr>(batch_.pixel_bytes), nullptr,
               GL_STREAM_READ);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  CheckGlError("Renderer::RenderBatch: making the framebuffer of layers");
}

void GlRenderer::PoseBatchHead(const BatchHead& head) {
  UpdatePoses(head.state);
  for (std::size_t i = 0; i < items_.size(); ++i) {
    const int object = items_[i].object;
    if (object < 0) continue;
    if (!head.hidden.empty() && head.hidden[object]) {
      item_poses_[i] = Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, -kHiddenDepth));
    } else if (!head.object_poses.empty() && head.object_poses[object].has_value()) {
      item_poses_[i] = *head.object_poses[object];
    }
  }
}

void GlRenderer::ConvertBatchPixels(std::size_t first, std::size_t count, uint8_t* out) {
  const int width = cameras_[0]->model.intrinsics().width();
  const int height = cameras_[0]->model.intrinsics().height();
  const std::size_t tile_rgba = static_cast<std::size_t>(width) * height * 4;
  // One map for all of [first, last).
  glBindBuffer(GL_PIXEL_PACK_BUFFER, batch_.pixels);
  const auto* rgba = static_cast<const uint8_t*>(glMapBufferRange(
      GL_PIXEL_PACK_BUFFER, 0, static_cast<GLsizeiptr>(count * tile_rgba), GL_MAP_READ_BIT));
  if (rgba == nullptr) {
    const GLenum error = glGetError();
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    throw Error(std::string("Renderer::RenderBatch: glMapBufferRange failed: ") +
                GlErrorName(error));
  }
  const std::size_t tile_rgb = static_cast<std::size_t>(width) * height * 3;
  // In parts on threads for a large batch (on an H200, N = 256 128 x 128 stereo pairs: the
  // readback 5.2 -> 1.7 ms); each context's threads share the cores with the other's.
  static const unsigned cores = std::thread::hardware_concurrency();  // asked once
  RgbaToRgbInParts(rgba, out + first * tile_rgb, count * static_cast<std::size_t>(width) * height,
                   cores / static_cast<unsigned>(std::max(1, batch_contexts_)));
  glUnmapBuffer(GL_PIXEL_PACK_BUFFER);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
}

void GlRenderer::BatchHelperDeleter::operator()(BatchHelper* helper) const { delete helper; }

}  // namespace saccade::render::gl
