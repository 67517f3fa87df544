// Batch rendering (Renderer::RenderBatch): N heads, each with its own state and its own
// placement of the scene's objects, drawn through every camera into one framebuffer of tiles
// and read back at once.
//
// Layout: the framebuffer is `columns` strips of tiles, each strip one image wide and `rows`
// images tall. Tile k = head * cameras + camera lies in strip k / rows, at height k % rows.
// The projection flips rows (flip_rows, as every camera pass), so a strip's memory order from
// glReadPixels is its tiles in order, each with row 0 at the top: one glReadPixels per strip
// into one pixel buffer gives the caller's heads x cameras x height x width layout directly,
// and one map reads it all. The draw calls are the single renderer's (DrawScene); what a batch
// saves is the per-call overhead: one framebuffer bind, one synchronisation and one readback
// for every image of every head, which is what dominates small images on llvmpipe.
//
// Two contexts (RendererOptions::batch_contexts): the second half of the tiles is drawn by a
// second renderer of the same scene, on a thread of its own (its context current there for
// good), into the same places of its own framebuffer of the same layout, and read back into
// its part of the caller's buffer. On llvmpipe the thread that issues draw calls does the
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
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_size);
  const int max_rows = std::max(1, static_cast<int>(max_size) / height);
  const int max_columns = std::max(1, static_cast<int>(max_size) / width);
  const int rows = static_cast<int>(std::min<std::size_t>(tiles, max_rows));
  const int columns = static_cast<int>((tiles + rows - 1) / rows);
  if (columns > max_columns) {
    throw InvalidArgument(fmt::format(
        "Renderer::RenderBatch: {} images of {} x {} do not fit the device's framebuffer ({} "
        "pixels a side); expected at most {}",
        tiles, width, height, max_size, static_cast<std::size_t>(max_rows) * max_columns));
  }

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
    // The second half of the tiles on the helper's context, the first half here, at the same
    // places in the same layout (the rasteriser's arithmetic depends on where a tile lies).
    const std::size_t middle = tiles / 2;
    batch_helper_->Start([&heads, middle, tiles, rows, columns, out](GlRenderer& helper) {
      helper.DrawBatchTiles(heads, middle, tiles, rows, columns, out);
    });
    try {
      DrawBatchTiles(heads, 0, middle, rows, columns, out);
    } catch (...) {
      batch_helper_->Wait(/*rethrow=*/false);
      throw;
    }
    batch_helper_->Wait(/*rethrow=*/true);
  } else {
    DrawBatchTiles(heads, 0, tiles, rows, columns, out);
  }
  stats_.frames += static_cast<int64_t>(heads.size());
  stats_.total_ms += Milliseconds(start, Clock::now());
}

void GlRenderer::DrawBatchTiles(const std::vector<BatchHead>& heads, std::size_t first,
                                std::size_t last, int rows, int columns, uint8_t* out) {
  const Clock::time_point start = Clock::now();
  context_.MakeCurrent();
  const int width = cameras_[0]->model.intrinsics().width();
  const int height = cameras_[0]->model.intrinsics().height();
  const std::size_t cameras = cameras_.size();

  // The framebuffer of tiles, (re)made when the batch outgrows it.
  if (batch_.framebuffer == 0 || columns > batch_.columns || rows > batch_.rows) {
    if (batch_.framebuffer != 0) {
      glDeleteFramebuffers(1, &batch_.framebuffer);
      const GLuint renderbuffers[] = {batch_.color, batch_.depth};
      glDeleteRenderbuffers(2, renderbuffers);
      glDeleteBuffers(1, &batch_.pixels);
    }
    batch_.columns = std::max(columns, batch_.columns);
    batch_.rows = std::max(rows, batch_.rows);
    const int fb_width = batch_.columns * width;
    const int fb_height = batch_.rows * height;
    glGenRenderbuffers(1, &batch_.color);
    glBindRenderbuffer(GL_RENDERBUFFER, batch_.color);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, fb_width, fb_height);
    glGenRenderbuffers(1, &batch_.depth);
    glBindRenderbuffer(GL_RENDERBUFFER, batch_.depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, fb_width, fb_height);
    glGenFramebuffers(1, &batch_.framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, batch_.framebuffer);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, batch_.color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, batch_.depth);
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      throw Error(fmt::format(
          "Renderer::RenderBatch: the {} x {} framebuffer of tiles is incomplete: status 0x{:04X}",
          fb_width, fb_height, status));
    }
    batch_.pixel_bytes = static_cast<std::size_t>(fb_width) * fb_height * 4;
    glGenBuffers(1, &batch_.pixels);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, batch_.pixels);
    glBufferData(GL_PIXEL_PACK_BUFFER, static_cast<GLsizeiptr>(batch_.pixel_bytes), nullptr,
                 GL_STREAM_READ);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    CheckGlError("Renderer::RenderBatch: making the framebuffer of tiles");
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

  glBindFramebuffer(GL_FRAMEBUFFER, batch_.framebuffer);
  glEnable(GL_SCISSOR_TEST);
  glViewport(0, 0, batch_.columns * width, batch_.rows * height);
  glScissor(0, 0, batch_.columns * width, batch_.rows * height);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  double pose_ms = 0.0;
  std::size_t posed = heads.size();  // the head whose poses item_poses_ holds
  for (std::size_t tile = first; tile < last; ++tile) {
    const std::size_t h = tile / cameras;
    const std::size_t c = tile % cameras;
    const BatchHead& head = heads[h];
    if (h != posed) {
      const Clock::time_point pose_start = Clock::now();
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
      posed = h;
      pose_ms += Milliseconds(pose_start, Clock::now());
    }
    const int x = static_cast<int>(tile / rows) * width;
    const int y = static_cast<int>(tile % rows) * height;
    glViewport(x, y, width, height);
    glScissor(x, y, width, height);
    DrawScene(batch_views_[c], cameras_[c]->clip.near, scene_.CameraPose(*cameras_[c], head.state));
  }
  glDisable(GL_SCISSOR_TEST);
  const Clock::time_point drawn = Clock::now();

  // Each strip's part of [first, last) into the pixel buffer, then one map for all of them.
  glBindFramebuffer(GL_READ_FRAMEBUFFER, batch_.framebuffer);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, batch_.pixels);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  const std::size_t tile_rgba = static_cast<std::size_t>(width) * height * 4;
  for (int column = 0; column < columns; ++column) {
    const std::size_t strip = static_cast<std::size_t>(column) * rows;
    const std::size_t from = std::max(first, strip);
    const std::size_t to = std::min(last, strip + static_cast<std::size_t>(rows));
    if (from >= to) continue;
    glReadPixels(column * width, static_cast<int>(from - strip) * height, width,
                 static_cast<int>(to - from) * height, GL_RGBA, GL_UNSIGNED_BYTE,
                 reinterpret_cast<void*>(from * tile_rgba));
  }
  const auto* rgba = static_cast<const uint8_t*>(
      glMapBufferRange(GL_PIXEL_PACK_BUFFER, static_cast<GLintptr>(first * tile_rgba),
                       static_cast<GLsizeiptr>((last - first) * tile_rgba), GL_MAP_READ_BIT));
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
  RgbaToRgbInParts(rgba, out + first * tile_rgb,
                   (last - first) * static_cast<std::size_t>(width) * height,
                   cores / static_cast<unsigned>(std::max(1, batch_contexts_)));
  glUnmapBuffer(GL_PIXEL_PACK_BUFFER);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  CheckGlError("Renderer::RenderBatch");
  const Clock::time_point end = Clock::now();

  stats_.scene_update_ms += pose_ms;
  stats_.draw_ms += Milliseconds(start, drawn) - pose_ms;
  stats_.readback_ms += Milliseconds(drawn, end);
}

void GlRenderer::BatchHelperDeleter::operator()(BatchHelper* helper) const { delete helper; }

}  // namespace saccade::render::gl
