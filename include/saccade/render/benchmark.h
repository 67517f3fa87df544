#pragma once
// The render benchmark behind `saccade bench`: timed stereo frames, pipelined as `saccade
// render` draws them, and the table of what each effect costs (docs/performance.md).
#include <algorithm>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "saccade/head/head_description.h"
#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"

namespace saccade::render {

// The head's pan rate while timing motion blur: fast enough that an exposure of a few
// milliseconds smears the image by pixels, so that the blur's sub-frames are really drawn.
inline constexpr double kBenchPanRate = 2.0;  // rad/s

/// One timed run: `frames` stereo frames after `warmup`, pipelined as `render` does.
struct Measurement {
  std::string device;
  std::vector<std::string> cameras;
  int frames = 0;
  double seconds = 0.0;
  int64_t pixels = 0;
  // Per frame, milliseconds (RenderStats).
  double update_ms = 0.0, draw_ms = 0.0, effects_ms = 0.0, readback_ms = 0.0;
  double cpu_effects_ms = 0.0;  ///< of readback_ms: the lens remap and noise on the CPU

  double fps() const { return frames / std::max(seconds, 1e-9); }
  double ms_per_frame() const { return 1000.0 * seconds / std::max(frames, 1); }
};

/// Times `frames` stereo frames after `warmup` untimed ones, the head's joints moving at
/// `joint_velocities`. `progress(done, fps)` is told every 10 frames and at the end.
Measurement Measure(const scene::Scene& scene, const RendererOptions& options,
                    const head::JointState& joint_velocities, int frames, int warmup,
                    const std::function<void(int done, double fps)>& progress = {});

/// One row of the effect table: a run with one effect on (or all, or none).
struct EffectRun {
  const char* name;   ///< JSON key
  const char* label;  ///< text table
  RendererOptions options;
  bool moving = false;       ///< the head pans at kBenchPanRate during the exposure
  std::string unconfigured;  ///< why the scene gives this effect nothing to do; empty: run
  std::optional<Measurement> result;
};

/// The runs of the effect table, all on `base`'s other options (MSAA, LOD, cameras).
std::vector<EffectRun> EffectRuns(const scene::Scene& scene, const RendererOptions& base,
                                  const std::vector<std::string>& cameras);

/// A finished `saccade bench`: the first figure (the options as given, the head still) and
/// the effect table, as JSON for scripts (docs/cli.md) and as text for people.
struct BenchReport {
  std::string scene_path;
  RendererOptions options;  ///< the first figure's
  int frames = 0, warmup = 0;
  int width = 0, height = 0;  ///< the first camera's image
  Measurement main;
  std::vector<EffectRun> runs;  ///< empty: --no-effect-table

  nlohmann::json Json() const;
  std::string Text() const;
};

/// `saccade bench` on a loaded scene (`scene_path` only names it in the report): the first
/// figure, then with `effect_table` every run of EffectRuns that the scene gives something to
/// do. `progress` as Measure's, for every run in turn.
BenchReport Bench(const std::string& scene_path, const scene::Scene& scene,
                  const RendererOptions& options, int frames, int warmup, bool effect_table,
                  const std::function<void(int done, double fps)>& progress = {});

}  // namespace saccade::render
