// render and bench: headless stereo capture to files, and the frames-per-second benchmark.

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "saccade/core/error.h"
#include "saccade/core/progress.h"
#include "saccade/record/frame_recorder.h"
#include "saccade/render/benchmark.h"
#include "saccade/render/dataset.h"
#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"

namespace saccade::app {
namespace {

using render::EffectRun;
using render::kBenchPanRate;
using render::Measure;
using render::Measurement;

using nlohmann::json;
namespace fs = std::filesystem;

std::atomic<bool> g_interrupted{false};
extern "C" void OnInterrupt(int) { g_interrupted = true; }

struct RenderOptions {
  std::string scene;
  std::string head;  ///< --head: replaces the scene's robot head
  std::string out;
  int frames = 1;
  double fps = 30.0;
  std::vector<double> joints;
  bool degrees = false;
  bool force = false;
  std::string truth;                          ///< --truth: "depth,ids,boxes" or a part of it
  const CLI::Option* truth_option = nullptr;  ///< whether --truth was given (even empty)
  render::RendererOptions renderer;           ///< --msaa, --lod-max-error, --no-distortion, ...
  std::vector<std::string> cameras;
  McapOptions record;  ///< --record FILE.mcap and its tuning
};

// Each frame to the data set folder and to the recording, when both are asked for.
class TeeSink final : public render::FrameSink {
 public:
  explicit TeeSink(std::vector<render::FrameSink*> sinks) : sinks_(std::move(sinks)) {}
  void Write(int64_t index, double time, const scene::SceneState& state,
             const std::vector<render::Frame>& frames) override {
    for (render::FrameSink* sink : sinks_) sink->Write(index, time, state, frames);
  }

 private:
  std::vector<render::FrameSink*> sinks_;
};

scene::SceneState StateFor(const scene::Scene& scene, const std::vector<double>& joints,
                           bool degrees) {
  scene::SceneState state = scene.InitialState();
  if (!joints.empty()) {
    if (!scene.robot()) throw InvalidArgument("--joints: the scene has no robot");
    state.joints = JointsFromArgs(scene.robot()->head, joints, degrees);
    scene.robot()->head.CheckLimits(state.joints.values());
  }
  return state;
}

int RunRender(const RenderOptions& o) {
  if (o.out.empty() && o.record.path.empty()) {
    throw InvalidArgument("render: nowhere to write: give --out DIR, --record FILE.mcap or both");
  }
  std::optional<record::RecorderOptions> recording;
  if (!o.record.path.empty()) recording = RecorderOptionsFor(o.record);
  const bool truth_given = o.truth_option != nullptr && o.truth_option->count() > 0;
  const render::TruthRequest truth =
      truth_given ? render::TruthRequest::Parse(o.truth) : render::TruthRequest{};
  const scene::Scene scene = scene::Scene::Load(o.scene, {o.head});
  const scene::SceneState initial = StateFor(scene, o.joints, o.degrees);
  render::RendererOptions options = o.renderer;
  options.cameras = o.cameras;
  render::ApplyTruth(truth, &options);
  if (truth.ids) render::CheckIdsFitPng16(scene, options);
  auto renderer = render::MakeRenderer(scene, options);
  const std::vector<std::string>& cameras = renderer->camera_names();
  const fs::path out(o.out);
  std::vector<render::FrameSink*> sinks;
  std::optional<render::DatasetWriter> writer;
  if (!o.out.empty()) {
    writer.emplace(scene, cameras, truth, out, o.force, options.distortion);
    sinks.push_back(&*writer);
  }
  std::optional<record::FrameRecorder> recorder;
  if (recording) {
    recording->metadata = RunMetadata("render", "", o.scene, o.head, "");
    if (scene.robot()) recording->metadata["head"] = scene.robot()->head.name();
    recording->metadata["cameras"] = "rendered";
    recording->metadata["fps"] = fmt::format("{}", o.fps);
    recorder.emplace(scene, truth, o.record.path, *recording);
    sinks.push_back(&*recorder);
  }
  TeeSink sink(sinks);
  auto previous_int = std::signal(SIGINT, OnInterrupt);
  auto previous_term = std::signal(SIGTERM, OnInterrupt);

  const ProgressBar progress(o.frames);
  const auto start = std::chrono::steady_clock::now();
  const int written =
      render::RenderDataset(*renderer, sink, initial, o.frames, o.fps, g_interrupted,
                            [&](int done, double fps) { progress.Update(done, fps); });
  progress.Finish();
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::string where = o.out;
  if (recorder) {
    const record::RecordingStats stats = recorder->Close();
    where += fmt::format("{}{} ({} messages, {:.1f} MB)", where.empty() ? "" : " and ",
                         o.record.path, stats.messages, stats.bytes / 1e6);
  }
  if (g_interrupted) {
    fmt::print(stderr, "interrupted: {} whole frames written to {}\n", written, where);
    return 130;
  }
  fmt::print("{} frames x {} cameras in {:.2f} s ({:.1f} fps) -> {}\n", written, cameras.size(),
             seconds, written / std::max(seconds, 1e-9), where);
  return 0;
}

// --- bench -------------------------------------------------------------------------------

struct BenchOptions {
  std::string scene = ShippedFile("scenes/bench.yaml");
  std::string head;         ///< --head: replaces the scene's robot head
  bool hide_robot = false;  ///< --hide-robot: the robot's body not drawn
  // 60 frames time a run to a few per cent; the effect table's seven runs then take about a
  // minute on llvmpipe (motion blur draws the scene blur_samples times per frame).
  int frames = 60;
  int warmup = 10;
  render::RendererOptions renderer;  ///< --msaa, --lod-max-error, --no-distortion, ...
  bool json = false;
  bool effect_table = true;
};

/// The scene with its robot's body hidden (--hide-robot): what the robot's own meshes cost.
scene::Scene WithoutRobotBody(const scene::Scene& scene) {
  std::optional<scene::Robot> robot = scene.robot();
  if (!robot) throw InvalidArgument("bench: --hide-robot: the scene has no robot");
  robot->visible = false;
  return scene::Scene(scene.background(), scene.lights(), scene.ground(), scene.objects(),
                      scene.cameras(), robot);
}

int RunBench(const BenchOptions& o) {
  scene::Scene scene = scene::Scene::Load(o.scene, {o.head});
  if (scene.cameras().empty()) throw InvalidArgument("bench: the scene has no cameras");
  if (o.hide_robot) scene = WithoutRobotBody(scene);
  std::optional<ProgressBar> bar;
  const auto progress = [&bar, &o](int done, double fps) {
    if (!bar) bar.emplace(o.frames);
    bar->Update(done, fps);
    if (done == o.frames) {
      bar->Finish();
      bar.reset();
    }
  };
  const render::BenchReport report =
      render::Bench(o.scene, scene, o.renderer, o.frames, o.warmup, o.effect_table, progress);
  if (o.json) {
    std::cout << report.Json().dump(2) << "\n";
  } else {
    fmt::print("{}", report.Text());
  }
  return 0;
}

/// Options shared by render and bench, straight into the renderer's options: --msaa,
/// --lod-max-error and the effect switches.
void AddRendererOptions(CLI::App* command, render::RendererOptions* options) {
  command->add_option("--msaa", options->msaa_samples, "Multisample anti-aliasing: 0, 2, 4 or 8")
      ->check(CLI::IsMember({0, 2, 4, 8}))
      ->capture_default_str();
  command
      ->add_option("--lod-max-error", options->lod_max_error_px,
                   "Levels of detail: draw dense meshes (1024+ triangles) simplified as long as "
                   "their geometric error stays within this many pixels on the image (PX); "
                   "0: full detail always")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command->add_flag_callback(
      "--no-distortion", [options] { options->distortion = false; },
      "Render every camera as the pinhole of its K, without its calibration's lens distortion "
      "(the frames' metadata and calibration files then say distortion none)");
  command->add_flag_callback(
      "--no-noise", [options] { options->noise = false; },
      "No sensor noise (the scene's sensor: read_noise_dn, gain_dn_per_e, or its EMVA 1288 "
      "sensor, emva)");
  command->add_flag_callback(
      "--no-blur", [options] { options->motion_blur = false; },
      "No motion blur (the scene's sensor: exposure, blur_samples): each frame an instant");
  command->add_flag_callback(
      "--no-optics", [options] { options->optics = false; },
      "No lens photometry (the scene's lens: vignetting, depth of field)");
  command->add_flag_callback(
      "--no-color", [options] { options->color = false; },
      "No sensor colour (the scene's sensor color: colour filter array, white balance, "
      "demosaicing, tone curve): the plain rendered RGB, and no raw mosaic");
  command->add_flag_callback(
      "--no-turn-blur", [options] { options->turn_blur = false; },
      "Motion blur of a turning camera draws every sub-frame, instead of a few drawn instants "
      "seen through the turn (used while the parallax and moving items depart from drawing by "
      "at most 1 px)");
}

}  // namespace

Runner AddRenderCommand(CLI::App& app) {
  auto o = std::make_shared<RenderOptions>();
  auto* render = app.add_subcommand(
      "render",
      "Render a scene headless to a data set with ground truth: its calibrated cameras, with "
      "lens distortion, sensor noise and motion blur as the scene describes them, to "
      "DIR/<camera>/<frame>.png, each camera's "
      "raw Bayer mosaic (DIR/<camera>/raw/<frame>.png) when the camera has a colour filter, its "
      "calibration as OpenCV YAML with the distortion that was rendered (DIR/<camera>.yaml, "
      "DIR/stereo.yaml for a head), and DIR/frames.jsonl with every frame's metadata; or to an "
      "MCAP recording of the same (--record FILE.mcap), or both. Ctrl-C stops after the frame "
      "in hand: only whole frames are left.");
  render->add_option("--scene", o->scene, "Scene YAML (scenes/portraits.yaml, ...)")
      ->check(CLI::ExistingFile)
      ->required();
  render
      ->add_option("--head", o->head,
                   "Head file (robots/*.yaml) in place of the scene's robot head, at its home "
                   "joints (--joints then are that head's)")
      ->check(CLI::ExistingFile);
  render->add_option("--out", o->out, "Output folder (the data set); --out, --record or both");
  render->add_option("--record", o->record.path,
                     "Also or instead: an MCAP recording (FILE.mcap) of every frame, as ROS 2 "
                     "messages: <camera>/image_raw, camera_info, /tf, joint_states, with --truth "
                     "<camera>/depth/image_raw (32FC1, m) and ids/image_raw (mono16), and each "
                     "frame's record (frames.jsonl's line) on /saccade/frames (docs/recording.md)");
  AddRecordTuning(render, o->record);
  render->add_option("--frames", o->frames, "Number of frames")
      ->check(CLI::Range(1, 100000000))
      ->capture_default_str();
  render->add_option("--fps", o->fps, "Simulated frames per second (frame i at time i / fps)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  render
      ->add_option("--joints", o->joints,
                   "One value per joint of the scene's head, in its order (POPEYE: PAN TILT LEFT "
                   "RIGHT); radians, or degrees with --deg; default: the scene's")
      ->expected(1, 64);
  render->add_flag("--deg", o->degrees, "--joints are in degrees");
  render->add_option("--camera", o->cameras, "Render only this camera (repeatable)");
  o->truth_option = render->add_option(
      "--truth", o->truth,
      "Ground truth, a comma-separated list of depth, ids, boxes (any subset), drawn at each "
      "frame's time without blur or noise, through the same lens as the image. depth: "
      "DIR/<camera>/depth/<frame>.png, 16-bit, the surface's z in the camera frame in "
      "millimetres (rounded to nearest; 0: no surface; 65535: 65.535 m or farther). ids: "
      "DIR/<camera>/ids/<frame>.png, 16-bit, the instance id each pixel sees (0: background "
      "and ground; a scene with an id above 65535 is refused). boxes: in frames.jsonl, the "
      "visible objects' ids, names, 2D boxes [x_min, y_min, x_max, y_max] (inclusive pixels), "
      "pixel counts and poses X_CO, X_WO (4x4, metres)");
  AddRendererOptions(render, &o->renderer);
  render->add_flag_callback(
      "--force", [o] { o->force = o->record.force = true; },
      "Replace output already in --out, or the --record file");
  return [o] { return RunRender(*o); };
}

Runner AddBenchCommand(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  auto* bench = app.add_subcommand(
      "bench",
      "Time the renderer in stereo frames per second: every camera rendered and its pixels in CPU "
      "memory, with the "
      "time per stage; then the cost of each effect (lens distortion, sensor noise, motion blur "
      "with the head panning at 2 rad/s, ground truth, all of them), each run alone with the "
      "others off, against a run with all of them off. The effect switches below apply to the "
      "first figure; the table sets them itself.");
  bench->add_option("--scene", o->scene, "Scene YAML")
      ->check(CLI::ExistingFile)
      ->capture_default_str();
  bench
      ->add_option("--head", o->head,
                   "Head file (robots/*.yaml) in place of the scene's robot head")
      ->check(CLI::ExistingFile);
  bench->add_flag("--hide-robot", o->hide_robot,
                  "Do not draw the robot's body (its URDF visuals): against a run without it, "
                  "what the robot's own meshes cost");
  bench
      ->add_option("--frames", o->frames,
                   "Frames to time, in each run (the first figure and each row of the effect "
                   "table)")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  bench->add_option("--warmup", o->warmup, "Frames rendered before timing (in each run)")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  AddRendererOptions(bench, &o->renderer);
  bench->add_flag_callback(
      "--no-effect-table", [o] { o->effect_table = false; },
      "Only the first figure: skip the runs that time each effect");
  bench->add_flag("--json", o->json, "Print JSON");
  return [o] { return RunBench(*o); };
}

}  // namespace saccade::app
