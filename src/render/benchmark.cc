#include "saccade/render/benchmark.h"

#include <fmt/format.h>

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
  m.cpu_effects_ms = (after.cpu_effects_ms - before.cpu_effects_ms) / frames;
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

namespace {
double OffMs(const std::vector<EffectRun>& runs) {
  return !runs.empty() && runs.front().result ? runs.front().result->ms_per_frame() : 0.0;
}
}  // namespace

BenchReport Bench(const std::string& scene_path, const scene::Scene& scene,
                  const RendererOptions& options, int frames, int warmup, bool effect_table,
                  const std::function<void(int done, double fps)>& progress) {
  // The first figure: the options as given, the head still.
  const Measurement main = Measure(scene, options, {}, frames, warmup, progress);
  std::vector<EffectRun> runs;
  if (effect_table) {
    runs = EffectRuns(scene, options, main.cameras);
    // The head's first joint (POPEYE's pan) turning, the others still.
    head::JointState panning;
    if (scene.robot()) {
      panning = head::JointState(scene.robot()->head.joint_names());
      panning[0] = kBenchPanRate;
    }
    for (EffectRun& run : runs) {
      if (!run.unconfigured.empty()) continue;
      run.result = Measure(scene, run.options, run.moving ? panning : head::JointState{}, frames,
                           warmup, progress);
    }
  }
  BenchReport report{scene_path, options, frames, warmup, 0, 0, main, runs};
  const scene::CameraSpec* first = scene.FindCamera(main.cameras.front());
  report.width = first->model.intrinsics().width();
  report.height = first->model.intrinsics().height();
  return report;
}

nlohmann::json BenchReport::Json() const {
  using nlohmann::json;
  const double off_ms = OffMs(runs);
  json effects = json::array();
  for (const EffectRun& run : runs) {
    json entry = {{"name", run.name},
                  {"configured", run.unconfigured.empty()},
                  {"head_pan_rad_per_s", run.moving ? kBenchPanRate : 0.0}};
    if (run.result) {
      entry["frames_per_second"] = run.result->fps();
      entry["ms_per_frame"] = run.result->ms_per_frame();
      entry["extra_ms"] = run.result->ms_per_frame() - off_ms;
    } else {
      entry["frames_per_second"] = entry["ms_per_frame"] = entry["extra_ms"] = nullptr;
      entry["note"] = run.unconfigured;
    }
    effects.push_back(entry);
  }
  return {{"scene", scene_path},
          {"device", main.device},
          {"cameras", main.cameras},
          {"width", width},
          {"height", height},
          {"msaa", options.msaa_samples},
          {"lod_max_error_px", options.lod_max_error_px},
          {"distortion", options.distortion},
          {"noise", options.noise},
          {"motion_blur", options.motion_blur},
          {"frames", frames},
          {"seconds", main.seconds},
          {"frames_per_second", main.fps()},
          {"megapixels_per_second", main.pixels / main.seconds / 1e6},
          {"ms_per_frame",
           {{"total", main.ms_per_frame()},
            {"scene_update", main.update_ms},
            {"draw", main.draw_ms},
            {"effects", main.effects_ms},
            {"readback", main.readback_ms},
            {"cpu_effects", main.cpu_effects_ms}}},
          {"effects", effects}};
}

std::string BenchReport::Text() const {
  const auto on_off = [](bool on) { return on ? "on" : "off"; };
  std::string out = fmt::format("scene    {}\ndevice   {}\n", scene_path, main.device);
  out += fmt::format(
      "cameras  {} x {}x{}, msaa {}, lod max error {} px; distortion {}, noise {}, motion blur "
      "{}\n",
      main.cameras.size(), width, height, options.msaa_samples, options.lod_max_error_px,
      on_off(options.distortion), on_off(options.noise), on_off(options.motion_blur));
  out += fmt::format(
      "{} frames ({} cameras each, pixels in CPU memory, head still) in {:.3f} s: {:.1f} "
      "frames/s, {:.1f} Mpixel/s\n",
      frames, main.cameras.size(), main.seconds, main.fps(), main.pixels / main.seconds / 1e6);
  out += fmt::format(
      "per frame: {:.2f} ms total; stages (CPU wall time, overlapping with the GPU):\n"
      "  scene update {:.2f} ms, draw {:.2f} ms, effects {:.2f} ms, readback {:.2f} ms{}\n",
      main.ms_per_frame(), main.update_ms, main.draw_ms, main.effects_ms, main.readback_ms,
      main.cpu_effects_ms > 0.0
          ? fmt::format(" (of which the lens remap and noise on the CPU {:.2f} ms)",
                        main.cpu_effects_ms)
          : std::string());
  if (runs.empty()) return out;
  const double off_ms = OffMs(runs);
  out += fmt::format(
      "\ncost of each effect ({} frames after {} warm-up each; effects off otherwise):\n", frames,
      warmup);
  out += fmt::format("  {:<26} {:>9} {:>10} {:>10}\n", "run", "frames/s", "ms/frame", "extra ms");
  for (const EffectRun& run : runs) {
    if (!run.result) {
      out += fmt::format("  {:<26} not run: {}\n", run.label, run.unconfigured);
    } else if (&run == &runs.front()) {
      out += fmt::format("  {:<26} {:>9.1f} {:>10.2f} {:>10}\n", run.label, run.result->fps(),
                         run.result->ms_per_frame(), "-");
    } else {
      out += fmt::format("  {:<26} {:>9.1f} {:>10.2f} {:>+10.2f}\n", run.label, run.result->fps(),
                         run.result->ms_per_frame(), run.result->ms_per_frame() - off_ms);
    }
  }
  return out;
}

}  // namespace saccade::render
