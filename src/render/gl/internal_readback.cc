// Retrieve: waits for the oldest submitted state's fence and reads every camera's pixels back
// from its pixel buffer objects into a pooled image, with the frame's metadata.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <exception>
#include <optional>
#include <thread>

#include "render/gl/internal_cpu_lens.h"
#include "render/gl/internal_gl_renderer_impl.h"
#include "render/gl/internal_pixels.h"
#include "saccade/core/error.h"
#include "saccade/geometry/image_camera.h"

namespace saccade::render::gl {
namespace {

// A commanded exposure and gain without an EMVA sensor: every 8-bit value times `factor`,
// rounded and clipped at 255 (the sensor saturates), through a table.
void ScaleBrightness(double factor, Image* image) {
  if (factor == 1.0) return;  // commanded as the file says
  std::array<uint8_t, 256> table;
  for (int v = 0; v < 256; ++v) {
    table[v] = static_cast<uint8_t>(std::min(255.0, std::round(v * factor)));
  }
  uint8_t* p = image->data();
  for (std::size_t i = 0, n = image->size_bytes(); i < n; ++i) p[i] = table[p[i]];
}

}  // namespace

std::shared_ptr<Image> GlRenderer::NewImage(int camera) {
  const geometry::Intrinsics& K = cameras_[camera]->model.intrinsics();
  std::vector<std::shared_ptr<Image>>& pool = image_pools_[camera];
  for (std::shared_ptr<Image>& image : pool) {
    // Only the pool holds it: the caller has let go of every frame that shared it.
    if (image.use_count() == 1) {
      std::atomic_thread_fence(std::memory_order_acquire);  // after the last reader's release
      return image;
    }
  }
  auto image = std::make_shared<Image>(K.width(), K.height(), PixelFormat::kRgb8);
  if (pool.size() < kPooledImagesPerCamera) pool.push_back(image);
  return image;
}

std::vector<Frame> GlRenderer::Retrieve() {
  if (in_flight_ == 0) {
    throw Error("Renderer::Retrieve: no state is in flight; Submit one first");
  }
  context_.MakeCurrent();
  const Clock::time_point start = Clock::now();
  const int slot = oldest_;
  Pending& pending = pending_[slot];
  GLenum status = GL_TIMEOUT_EXPIRED;
  while (status == GL_TIMEOUT_EXPIRED) {
    status = glClientWaitSync(pending.fence, GL_SYNC_FLUSH_COMMANDS_BIT,
                              GLuint64{1'000'000'000});  // 1 s, then again
  }
  glDeleteSync(pending.fence);
  pending.fence = nullptr;
  oldest_ = (oldest_ + 1) % CameraTarget::kSlots;
  --in_flight_;
  if (status == GL_WAIT_FAILED) {
    throw Error("Renderer::Retrieve: glClientWaitSync failed: " + GlErrorName(glGetError()));
  }

  std::vector<Frame> frames;
  frames.reserve(cameras_.size());
  std::vector<ChainJob> jobs(cameras_.size());
  for (std::size_t i = 0; i < cameras_.size(); ++i) {
    const CameraSetup& setup = setups_[i];
    std::shared_ptr<Image> image = NewImage(static_cast<int>(i));
    Describe(static_cast<int>(i), pending, &image->metadata());
    const std::size_t pixel_count =
        static_cast<std::size_t>(image->width()) * static_cast<std::size_t>(image->height());
    // One path for every camera: the effect target's colour buffers when effects run (its
    // source view's when the CPU remaps the lens, its stretches' when the CPU fetches a turn),
    // else the plain target; a tightly packed RGB row is copied as it is.
    const bool cpu_lens = pending.cpu_lens[i];
    const CpuTurn* cpu_turn = pending.cpu_turn[i] ? &*pending.cpu_turn[i] : nullptr;
    const PixelBuffers* effect_buffers = !setup.effects ? nullptr
                                         : cpu_turn     ? &setup.effects->stretch_buffers()
                                         : cpu_lens     ? &setup.effects->source_buffers()
                                                        : &setup.effects->color_buffers();
    const uint8_t* pixels = effect_buffers != nullptr ? MapOrThrow(*effect_buffers, slot, "")
                                                      : MapOrThrow(*targets_[i], slot, "");
    const int row_bytes = setup.effects ? 4 * image->width() : targets_[i]->row_bytes();
    const std::optional<NoiseParams>& noise = pending.cpu_noise[i];
    if (cpu_lens || cpu_turn != nullptr || noise.has_value()) {
      std::optional<CpuNoise> cpu_noise;
      if (noise.has_value()) {
        cpu_noise = CpuNoise{noise->key, noise->read_sigma_dn, noise->gain_dn_per_e,
                             PackedGaussianTable().data(), LevelsFor(*noise)};
      }
      const auto convert = [&](int first_row, int end_row) {
        ConvertRows(static_cast<int>(i), cpu_lens, cpu_turn, pixels,
                    cpu_noise ? &*cpu_noise : nullptr, image.get(), first_row, end_row);
      };
      // A large image in chunks of rows on every core (the bench scene's 1024 x 768 eyes, lens
      // and noise: 3 to 5 ms a camera on the 2-core development machine).
      const Clock::time_point converting = Clock::now();
      InRowChunks(image->height(), pixel_count, convert);
      stats_.cpu_effects_ms += Milliseconds(converting, Clock::now());
    } else if (row_bytes == static_cast<int>(image->stride())) {
      std::memcpy(image->data(), pixels, image->size_bytes());
    } else {
      // RGBA rows to RGB in chunks of rows on every core (a GPU's frame is mostly this).
      const std::size_t width = static_cast<std::size_t>(image->width());
      InRowChunks(image->height(), pixel_count, [&](int first_row, int end_row) {
        RgbaToRgb(pixels + 4 * width * first_row, image->row(first_row),
                  width * static_cast<std::size_t>(end_row - first_row));
      });
    }
    if (effect_buffers != nullptr) {
      effect_buffers->Unmap();
    } else {
      targets_[i]->Unmap();
    }
    Frame frame{image, nullptr, nullptr, {}, nullptr};
    ChainJob& job = jobs[i];
    const bool dof = setup.chain && setup.chain->depth_of_field();
    if (setup.effects && setup.effects->has_color_depth()) {
      job.depth = ColorPassDepth(static_cast<int>(i), slot, *image);
    } else if (setup.truth) {
      FillTruth(static_cast<int>(i), pending, slot, &frame, dof ? &job.depth : nullptr);
    }
    job.image = image.get();
    job.frame_index = pending.frame_index;
    job.controls = scene_.ControlsOf(*cameras_[i], pending.state);
    if (setup.late_noise)
      job.levels = LevelsFor(LateNoiseParams(static_cast<int>(i), job.frame_index));
    frames.push_back(std::move(frame));
  }
  ApplyChains(&jobs, &frames);
  ++stats_.frames;
  const Clock::time_point end = Clock::now();
  stats_.readback_ms += Milliseconds(start, end);
  stats_.total_ms += Milliseconds(start, end);
  return frames;
}

bool GlRenderer::HasChainWork(int camera, const ChainJob& job) const {
  const CameraSetup& setup = setups_[camera];
  return setup.chain != nullptr || setup.late_noise || job.controls.commanded ||
         (options_.noise && cameras_[camera]->sensor.emva.has_value());
}

void GlRenderer::ApplyChains(std::vector<ChainJob>* jobs, std::vector<Frame>* frames) {
  std::vector<std::size_t> work;
  for (std::size_t i = 0; i < jobs->size(); ++i) {
    if (HasChainWork(static_cast<int>(i), (*jobs)[i])) work.push_back(i);
  }
  if (work.empty()) return;
  if (sensor_models_.size() != cameras_.size()) sensor_models_.resize(cameras_.size());
  const Clock::time_point start = Clock::now();
  // Every camera's chain is its own (its image, its frame, its sensor model): two cameras at
  // once where there are two cores (a stereo head's eyes), the same bits either way.
  std::exception_ptr errors[2];
  const auto run = [&](int worker, int workers) {
    try {
      for (std::size_t k = static_cast<std::size_t>(worker); k < work.size(); k += workers) {
        const std::size_t i = work[k];
        ApplyChain(static_cast<int>(i), (*jobs)[i], &(*frames)[i]);
      }
    } catch (...) {
      errors[worker] = std::current_exception();
    }
  };
  static const bool cores = std::thread::hardware_concurrency() >= 2;  // asked once
  if (cores && work.size() >= 2) {
    std::thread other(run, 1, 2);
    run(0, 2);
    other.join();
  } else {
    run(0, 1);
  }
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
  stats_.cpu_effects_ms += Milliseconds(start, Clock::now());
}

void GlRenderer::ApplyChain(int camera, const ChainJob& job, Frame* frame) {
  const CameraSetup& setup = setups_[camera];
  const CameraChain* chain = setup.chain.get();
  Image* image = job.image;
  // A Bayer sensor's photosites see one colour each: the EMVA sensor exposes the mosaic (a
  // value a pixel, not three), which demosaicing then spreads as a real camera's does.
  const bool bayer_sensor =
      chain != nullptr && chain->cfa() && options_.noise && cameras_[camera]->sensor.emva;
  std::optional<Image> mosaic;
  if (chain != nullptr && chain->optics()) {
    // The frame's values, resolved once: the focus distance commanded, else the scene's.
    const FrameOptics optics = chain->FrameOf(job.controls.focus_m);
    if (bayer_sensor && !setup.late_noise) {
      mosaic = chain->ApplyOpticsToMosaic(image, job.depth.get(), optics);  // the same bits
    } else {
      chain->ApplyOptics(image, job.depth.get(), optics);
    }
  }
  if (setup.late_noise) ApplyLateNoise(camera, job.frame_index, job.levels, image);
  if (bayer_sensor) {
    if (!mosaic) mosaic = Mosaic(image->view(), chain->color_options().cfa);
    ApplySensor(camera, job.controls, &*mosaic);
    frame->raw = chain->ApplyColor(image, &*mosaic);
    return;
  }
  ApplySensor(camera, job.controls, image);
  if (chain != nullptr && chain->color()) frame->raw = chain->ApplyColor(image);
}

NoiseParams GlRenderer::LateNoiseParams(int camera, int64_t frame_index) const {
  const scene::CameraSpec& spec = *cameras_[camera];
  NoiseParams params;
  params.read_sigma_dn = static_cast<float>(spec.sensor.read_noise_dn);
  params.gain_dn_per_e = static_cast<float>(spec.sensor.gain_dn_per_e);
  params.key = NoiseKey(spec.sensor.seed, spec.name, frame_index);
  return params;
}

void GlRenderer::ApplyLateNoise(int camera, int64_t frame_index, const uint8_t* levels,
                                Image* image) const {
  const NoiseParams params = LateNoiseParams(camera, frame_index);
  const CpuNoise noise{params.key, params.read_sigma_dn, params.gain_dn_per_e,
                       PackedGaussianTable().data(), levels};
  const int width = image->width();
  std::vector<uint8_t> rgba(4 * static_cast<std::size_t>(width), 255);
  for (int y = 0; y < image->height(); ++y) {
    uint8_t* row = image->row(y);
    for (int x = 0; x < width; ++x) {
      std::memcpy(&rgba[4 * static_cast<std::size_t>(x)], row + 3 * x, 3);
    }
    RgbaRowToRgbWithNoise(rgba.data(), row, width, y, noise);
  }
}

void GlRenderer::ApplySensor(int camera, const scene::AppliedControls& controls, Image* image) {
  const scene::CameraSpec& spec = *cameras_[camera];
  const bool emva = options_.noise && spec.sensor.emva;
  if (!emva) {
    if (controls.commanded) ScaleBrightness(controls.BrightnessFactor(), image);
    return;
  }
  std::unique_ptr<SensorModel>& model = sensor_models_[camera];  // sized by ApplyChains
  // A Bayer camera's sensor exposes the mosaic (one channel) with the colour on, the RGB image
  // (three) without it: remade when that changes (seeded per frame: a new renderer's frames).
  const int channels = IsBayer(image->format()) ? 1 : 3;
  if (!model || model->channels() != channels) {
    model = std::make_unique<SensorModel>(*spec.sensor.emva, spec.sensor.seed, spec.name,
                                          image->width(), image->height(), channels);
  }
  model->ExposeRendered8(image->view(), controls.exposure_s, image->metadata().frame_index, image,
                         controls.GainFactor());
}

const uint8_t* GlRenderer::LevelsFor(const NoiseParams& noise) {
  std::vector<uint8_t>& levels = noise_levels_[{noise.read_sigma_dn, noise.gain_dn_per_e}];
  if (levels.empty()) levels = NoiseLevels(noise.read_sigma_dn, noise.gain_dn_per_e);
  return levels.data();
}

void GlRenderer::ConvertRows(int camera, bool lens, const CpuTurn* turn, const uint8_t* pixels,
                             const CpuNoise* noise, Image* image, int first_row,
                             int end_row) const {
  const int width = image->width();
  if (turn != nullptr) {
    std::vector<uint8_t> row(4 * static_cast<std::size_t>(width));
    for (int y = first_row; y < end_row; ++y) {
      TurnBlurRow(*turn, pixels, width, image->height(), y, row.data());
      uint8_t* out = image->data() + static_cast<std::size_t>(y) * image->stride();
      if (noise != nullptr) {
        RgbaRowToRgbWithNoise(row.data(), out, width, y, *noise);
      } else {
        RgbaToRgb(row.data(), out, static_cast<std::size_t>(width));
      }
    }
    return;
  }
  if (!lens) {
    RgbaToRgbWithNoise(pixels, image->data(), width, first_row, end_row, *noise);
    return;
  }
  const CpuLens& cpu_lens = *setups_[static_cast<std::size_t>(camera)].effects->cpu_lens();
  std::vector<uint8_t> row(4 * static_cast<std::size_t>(width));
  for (int y = first_row; y < end_row; ++y) {
    cpu_lens.RemapRow(pixels, y, row.data());
    uint8_t* out = image->data() + static_cast<std::size_t>(y) * image->stride();
    if (noise != nullptr) {
      RgbaRowToRgbWithNoise(row.data(), out, width, y, *noise);
    } else {
      RgbaToRgb(row.data(), out, static_cast<std::size_t>(width));
    }
  }
}

void GlRenderer::Describe(int camera_index, const Pending& pending, ImageMetadata* out) const {
  const scene::CameraSpec& camera = *cameras_[camera_index];
  const CameraSetup& setup = setups_[camera_index];
  const std::size_t i = static_cast<std::size_t>(camera_index);
  ImageMetadata& meta = *out;
  meta.camera = camera.name;
  meta.time = pending.state.time;
  meta.frame_index = pending.frame_index;
  // The image as rendered: the lens's distortion, or a pinhole when distortion is off (or the
  // lens has none).
  geometry::SetCameraModel(meta, setup.rendered);
  geometry::SetCameraPose(meta, pending.X_WC[i]);
  meta.exposure_samples = pending.exposure_samples[i];
  const scene::AppliedControls controls = scene_.ControlsOf(camera, pending.state);
  meta.exposure_s = controls.exposure_s;
  meta.gain_db = controls.gain_db;
  meta.focus_m = controls.focus_m;
  meta.has_joints = camera.mount != scene::CameraMount::kWorld;
  meta.joints.clear();
  meta.joint_names.reset();
  if (meta.has_joints) {
    const head::JointState& q = pending.state.joints;
    meta.joints.assign(q.values().data(), q.values().data() + q.size());
    meta.joint_names = q.shared_names();
  }
}

}  // namespace saccade::render::gl
