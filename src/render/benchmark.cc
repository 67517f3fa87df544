#include "saccade/render/benchmark.h"

#include <algorithm>
#include <chrono>

namespace saccade::render {

Measurement Measure(const scene::Scene& scene, const RendererOptions& options,
                    const head::JointState& joint_velocities, int frames, int warmup,
                    const std::function<void(int done, double fps)>& progress) {
  auto renderer = MakeRenderer(scene, options);
  scene::SceneState initial = scene.InitialState();
  initial.joint_velocities = joint_velocities;
  auto state_at = [&](int i) {
    scene::SceneState state = initial;
    state.time = i / 30.0;
    return state;
  };
  for (int i = 0; i < warmup; ++i) renderer->Render(state_at(i), i);
  const RenderStats before = renderer->stats();
  const auto start = std::chrono::steady_clock::now();
  renderer->Submit(state_at(0), 0);
  Measurement m;
  for (int i = 0; i < frames; ++i) {
    if (i + 1 < frames) renderer->Submit(state_at(i + 1), i + 1);
    for (const auto& frame : renderer->Retrieve()) {
      m.pixels += static_cast<int64_t>(frame.color->width()) * frame.color->height();
    }
    if (i % 10 == 9) {
      const double s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (progress) progress(i + 1, (i + 1) / s);
    }
  }
  m.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (progress && frames % 10 != 0) progress(frames, frames / std::max(m.seconds, 1e-9));
  const RenderStats& after = renderer->stats();
  m.frames = frames;
  m.update_ms = (after.scene_update_ms - before.scene_update_ms) / frames;
  m.draw_ms = (after.draw_ms - before.draw_ms) / frames;
  m.effects_ms = (after.effects_ms - before.effects_ms) / frames;
  m.readback_ms = (after.readback_ms - before.readback_ms) / frames;
  m.device = renderer->DeviceDescription();
  m.cameras = renderer->camera_names();
  return m;
}

/// The runs of the effect table, all on `base`'s other options (MSAA, LOD, cameras).
std::vector<EffectRun> EffectRuns(const scene::Scene& scene, const RendererOptions& base,
                                  const std::vector<std::string>& cameras) {
  bool has_distortion = false, has_noise = false, has_blur = false;
  for (const auto& name : cameras) {
    const scene::CameraSpec& camera = *scene.FindCamera(name);
    has_distortion = has_distortion || !camera.model.distortion().IsIdentity();
    has_noise = has_noise || camera.sensor.HasNoise();
    has_blur = has_blur || camera.sensor.HasBlur();
  }
  RendererOptions off = base;
  off.distortion = off.noise = off.motion_blur = false;
  off.truth_depth = off.truth_ids = off.truth_objects = false;
  RendererOptions distortion = off, noise = off, blur = off, truth = off, all = off;
  distortion.distortion = true;
  noise.noise = true;
  blur.motion_blur = true;
  truth.truth_depth = truth.truth_ids = truth.truth_objects = true;
  all.distortion = all.noise = all.motion_blur = true;
  all.truth_depth = all.truth_ids = all.truth_objects = true;
  const auto unless = [](bool configured, const char* why) {
    return configured ? std::string() : std::string(why);
  };
  std::vector<EffectRun> runs;
  const auto add = [&runs](const char* name, const char* label, const RendererOptions& options,
                           bool moving, std::string unconfigured) {
    runs.push_back(EffectRun{name, label, options, moving, std::move(unconfigured), std::nullopt});
  };
  add("off", "effects off", off, false, "");
  add("distortion", "lens distortion", distortion, false,
      unless(has_distortion, "no camera of the scene has a lens distortion"));
  add("noise", "sensor noise", noise, false,
      unless(has_noise, "no camera of the scene has read or shot noise"));
  add("motion_blur", "motion blur, pan 2 rad/s", blur, true,
      unless(has_blur,
             "blur is not configured: no camera of the scene has an exposure (sensor: "
             "exposure_ms) with blur_samples > 1"));
  add("truth", "truth depth+ids+boxes", truth, false, "");
  add("all", "everything, pan 2 rad/s", all, true, "");
  return runs;
}

}  // namespace saccade::render
