// render and bench: headless stereo capture to files, and the frames-per-second benchmark.

#include <fmt/format.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "saccade/core/error.h"
#include "saccade/core/image_io.h"
#include "saccade/geometry/calibration_io.h"
#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"

namespace saccade::app {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

std::atomic<bool> g_interrupted{false};
extern "C" void OnInterrupt(int) { g_interrupted = true; }

/// Progress on a terminal: "[#####.....]  12/100 frames  25.3 fps", redrawn in place.
class ProgressBar {
 public:
  explicit ProgressBar(int total) : total_(total), enabled_(::isatty(STDERR_FILENO) != 0) {}
  void Update(int done, double fps) const {
    if (!enabled_) return;
    constexpr int kWidth = 30;
    const int filled = total_ > 0 ? done * kWidth / total_ : kWidth;
    std::fprintf(stderr, "\r[%s%s] %d/%d frames  %.1f fps", std::string(filled, '#').c_str(),
                 std::string(kWidth - filled, '.').c_str(), done, total_, fps);
    std::fflush(stderr);
  }
  void Finish() const {
    if (enabled_) std::fprintf(stderr, "\n");
  }

 private:
  int total_;
  bool enabled_;
};

json MatrixJson(const double* m, int rows, int cols) {
  json out = json::array();
  for (int r = 0; r < rows; ++r) {
    json row = json::array();
    for (int c = 0; c < cols; ++c) row.push_back(m[r * cols + c]);
    out.push_back(row);
  }
  return out;
}

/// One line of frames.jsonl: a frame index, its time and every camera's image and metadata.
json FrameJson(int64_t index, double time, const std::vector<render::Frame>& frames) {
  json cameras = json::object();
  for (const auto& frame : frames) {
    const ImageMetadata& m = frame.color->metadata();
    json entry = {{"file", fmt::format("{}/{:06d}.png", m.camera, index)},
                  {"width", frame.color->width()},
                  {"height", frame.color->height()},
                  {"K", MatrixJson(m.K.data(), 3, 3)},
                  {"distortion", {{"model", m.distortion_model}, {"coefficients", m.distortion}}},
                  {"X_WC", MatrixJson(m.X_WC.data(), 4, 4)}};
    if (m.has_joints) {
      entry["joints"] = {{"pan", m.joints[0]},
                         {"tilt", m.joints[1]},
                         {"left", m.joints[2]},
                         {"right", m.joints[3]}};
    }
    cameras[m.camera] = entry;
  }
  return {{"frame", index}, {"time", time}, {"cameras", cameras}};
}

/// The output folder: created if missing; one that already holds saccade output is refused
/// unless `force`, in which case the old output of these cameras is removed first.
void PrepareOutput(const fs::path& out, const std::vector<std::string>& cameras, bool force) {
  std::error_code error;
  if (fs::exists(out) && !fs::is_directory(out)) {
    throw InvalidArgument(
        fmt::format("render: --out {}: exists and is not a folder", out.string()));
  }
  std::vector<fs::path> existing;
  if (fs::exists(out / "frames.jsonl")) existing.push_back(out / "frames.jsonl");
  for (const auto& camera : cameras) {
    if (fs::exists(out / camera)) existing.push_back(out / camera);
    if (fs::exists(out / (camera + ".yaml"))) existing.push_back(out / (camera + ".yaml"));
  }
  if (fs::exists(out / "stereo.yaml")) existing.push_back(out / "stereo.yaml");
  if (!existing.empty() && !force) {
    throw InvalidArgument(
        fmt::format("render: --out {} already holds output ({}); pass --force to replace it",
                    out.string(), existing.front().filename().string()));
  }
  for (const auto& path : existing) {
    if (fs::is_directory(path)) {
      // Only our own frames: a camera folder holding anything else is left alone.
      for (const auto& entry : fs::directory_iterator(path)) {
        if (entry.path().extension() == ".png") fs::remove(entry.path());
      }
    } else {
      fs::remove(path);
    }
  }
  fs::create_directories(out, error);
  if (error) {
    throw FileError(out.string(), 0, "",
                    fmt::format("cannot create the folder: {}", error.message()));
  }
  for (const auto& camera : cameras) fs::create_directories(out / camera);
}

void WriteCalibrations(const scene::Scene& scene, const scene::SceneState& state,
                       const std::vector<std::string>& cameras, const fs::path& out) {
  // Frames are pinhole images for now (lens distortion is not rendered yet): the files
  // written describe the images as they are, with the camera's K and no distortion.
  for (const auto& name : cameras) {
    const scene::CameraSpec* camera = scene.FindCamera(name);
    if (!camera->model.distortion().IsIdentity()) {
      fmt::print(stderr,
                 "warning: camera {}: {} distortion is not rendered yet; its images and "
                 "calibration file are pinhole (K only)\n",
                 name, geometry::ToString(camera->model.distortion().model()));
    }
    geometry::WriteCameraCalibration({geometry::CameraModel(camera->model.intrinsics()), name},
                                     out / (name + ".yaml"),
                                     geometry::CalibrationFormat::kOpenCvYaml);
  }
  // The stereo pair's extrinsics at these joints (cv::stereoCalibrate's R, T).
  const scene::CameraSpec* left = scene.FindCamera("left");
  const scene::CameraSpec* right = scene.FindCamera("right");
  if (left == nullptr || right == nullptr) return;
  if (left->model.intrinsics().width() != right->model.intrinsics().width() ||
      left->model.intrinsics().height() != right->model.intrinsics().height()) {
    return;  // OpenCV's stereo files hold one image size
  }
  const geometry::Pose X_RL =
      scene.CameraPose(*right, state).inverse() * scene.CameraPose(*left, state);
  geometry::StereoCalibration stereo{geometry::CameraModel(left->model.intrinsics()),
                                     geometry::CameraModel(right->model.intrinsics()),
                                     X_RL.linear(), X_RL.translation()};
  geometry::WriteStereoCalibration(stereo, out / "stereo.yaml",
                                   geometry::CalibrationFormat::kOpenCvYaml);
}

struct RenderOptions {
  std::string scene;
  std::string out;
  int frames = 1;
  double fps = 30.0;
  std::vector<double> joints;
  bool degrees = false;
  bool force = false;
  render::RendererOptions renderer;  ///< --msaa, --lod-max-error
  std::vector<std::string> cameras;
};

scene::SceneState StateFor(const scene::Scene& scene, const std::vector<double>& joints,
                           bool degrees) {
  scene::SceneState state = scene.InitialState();
  if (!joints.empty()) {
    state.joints = JointsFromArgs(joints, degrees);
    if (!scene.robot()) throw InvalidArgument("--joints: the scene has no robot");
    scene.robot()->head.CheckLimits(state.joints);
  }
  return state;
}

int RunRender(const RenderOptions& o) {
  const scene::Scene scene = scene::Scene::Load(o.scene);
  const scene::SceneState initial = StateFor(scene, o.joints, o.degrees);
  render::RendererOptions options = o.renderer;
  options.cameras = o.cameras;
  auto renderer = render::MakeRenderer(scene, options);
  const std::vector<std::string>& cameras = renderer->camera_names();
  const fs::path out(o.out);
  PrepareOutput(out, cameras, o.force);
  WriteCalibrations(scene, initial, cameras, out);

  std::ofstream index(out / "frames.jsonl");
  if (!index) throw FileError((out / "frames.jsonl").string(), 0, "", "cannot write");
  auto previous_int = std::signal(SIGINT, OnInterrupt);
  auto previous_term = std::signal(SIGTERM, OnInterrupt);

  const ProgressBar progress(o.frames);
  const auto start = std::chrono::steady_clock::now();
  int written = 0;
  auto state_at = [&](int i) {
    scene::SceneState state = initial;
    state.time = i / o.fps;
    return state;
  };
  // Two states in flight: frame i + 1 is drawn while frame i is read back and encoded.
  renderer->Submit(state_at(0), 0);
  for (int i = 0; i < o.frames && !g_interrupted; ++i) {
    if (i + 1 < o.frames) renderer->Submit(state_at(i + 1), i + 1);
    std::vector<render::Frame> frames = renderer->Retrieve();
    std::vector<std::future<void>> writes;
    for (const auto& frame : frames) {
      writes.push_back(std::async(std::launch::async, [&out, &frame, i] {
        WritePng(frame.color->view(),
                 out / frame.color->metadata().camera / fmt::format("{:06d}.png", i));
      }));
    }
    for (auto& w : writes) w.get();  // rethrows a write error
    // The index line comes last: a frame listed in frames.jsonl has all its images.
    index << FrameJson(i, state_at(i).time, frames).dump() << "\n" << std::flush;
    ++written;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    progress.Update(written, written / std::max(seconds, 1e-9));
  }
  progress.Finish();
  std::signal(SIGINT, previous_int);
  std::signal(SIGTERM, previous_term);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (g_interrupted) {
    fmt::print(stderr, "interrupted: {} whole frames written to {}\n", written, out.string());
    return 130;
  }
  fmt::print("{} frames x {} cameras in {:.2f} s ({:.1f} fps) -> {}\n", written, cameras.size(),
             seconds, written / std::max(seconds, 1e-9), out.string());
  return 0;
}

struct BenchOptions {
  std::string scene = ShippedFile("scenes/bench.yaml");
  int frames = 200;
  int warmup = 10;
  render::RendererOptions renderer;  ///< --msaa, --lod-max-error
  bool json = false;
};

int RunBench(const BenchOptions& o) {
  const scene::Scene scene = scene::Scene::Load(o.scene);
  auto renderer = render::MakeRenderer(scene, o.renderer);
  const scene::SceneState initial = scene.InitialState();
  auto state_at = [&](int i) {
    scene::SceneState state = initial;
    state.time = i / 30.0;
    return state;
  };
  for (int i = 0; i < o.warmup; ++i) renderer->Render(state_at(i), i);
  const render::RenderStats before = renderer->stats();
  const ProgressBar progress(o.frames);
  const auto start = std::chrono::steady_clock::now();
  renderer->Submit(state_at(0), 0);
  int64_t pixels = 0;
  for (int i = 0; i < o.frames; ++i) {
    if (i + 1 < o.frames) renderer->Submit(state_at(i + 1), i + 1);
    for (const auto& frame : renderer->Retrieve()) {
      pixels += static_cast<int64_t>(frame.color->width()) * frame.color->height();
    }
    if (i % 10 == 9) {
      const double s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      progress.Update(i + 1, (i + 1) / s);
    }
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  progress.Finish();
  const render::RenderStats& after = renderer->stats();
  const double n = o.frames;
  const double update = (after.scene_update_ms - before.scene_update_ms) / n;
  const double draw = (after.draw_ms - before.draw_ms) / n;
  const double readback = (after.readback_ms - before.readback_ms) / n;
  const double fps = n / seconds;
  const auto& cameras = renderer->camera_names();
  const auto* first = scene.FindCamera(cameras.front());
  if (o.json) {
    json out = {{"scene", o.scene},
                {"device", renderer->DeviceDescription()},
                {"cameras", cameras},
                {"width", first->model.intrinsics().width()},
                {"height", first->model.intrinsics().height()},
                {"msaa", o.renderer.msaa_samples},
                {"lod_max_error_px", o.renderer.lod_max_error_px},
                {"frames", o.frames},
                {"seconds", seconds},
                {"frames_per_second", fps},
                {"megapixels_per_second", pixels / seconds / 1e6},
                {"ms_per_frame",
                 {{"total", 1000.0 / fps},
                  {"scene_update", update},
                  {"draw", draw},
                  {"readback", readback}}}};
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  fmt::print("scene    {}\ndevice   {}\n", o.scene, renderer->DeviceDescription());
  fmt::print("cameras  {} x {}x{}, msaa {}, lod max error {} px\n", cameras.size(),
             first->model.intrinsics().width(), first->model.intrinsics().height(),
             o.renderer.msaa_samples, o.renderer.lod_max_error_px);
  fmt::print(
      "{} frames ({} cameras each, pixels in CPU memory) in {:.3f} s: {:.1f} frames/s, "
      "{:.1f} Mpixel/s\n",
      o.frames, cameras.size(), seconds, fps, pixels / seconds / 1e6);
  fmt::print(
      "per frame: {:.2f} ms total; stages (CPU wall time, overlapping with the GPU):\n"
      "  scene update {:.2f} ms, draw {:.2f} ms, readback {:.2f} ms\n",
      1000.0 / fps, update, draw, readback);
  return 0;
}

/// --msaa and --lod-max-error, shared by render and bench, straight into the renderer's options.
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
}

}  // namespace

Runner AddRenderCommand(CLI::App& app) {
  auto o = std::make_shared<RenderOptions>();
  auto* render = app.add_subcommand(
      "render",
      "Render a scene headless through its calibrated cameras: DIR/<camera>/<frame>.png, each "
      "camera's calibration as OpenCV YAML (DIR/<camera>.yaml, DIR/stereo.yaml for a head), and "
      "DIR/frames.jsonl with every frame's metadata. Ctrl-C stops after the frame in hand: "
      "only whole frames are left.");
  render->add_option("--scene", o->scene, "Scene YAML (scenes/portraits.yaml, ...)")
      ->check(CLI::ExistingFile)
      ->required();
  render->add_option("--out", o->out, "Output folder")->required();
  render->add_option("--frames", o->frames, "Number of frames")
      ->check(CLI::Range(1, 100000000))
      ->capture_default_str();
  render->add_option("--fps", o->fps, "Simulated frames per second (frame i at time i / fps)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  render
      ->add_option("--joints", o->joints,
                   "PAN TILT LEFT RIGHT of the head (radians, or degrees with --deg); "
                   "default: the scene's")
      ->expected(4);
  render->add_flag("--deg", o->degrees, "--joints are in degrees");
  render->add_option("--camera", o->cameras, "Render only this camera (repeatable)");
  AddRendererOptions(render, &o->renderer);
  render->add_flag("--force", o->force, "Replace output already in --out");
  return [o] { return RunRender(*o); };
}

Runner AddBenchCommand(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  auto* bench = app.add_subcommand(
      "bench",
      "Stereo frames per second: every camera rendered and its pixels in CPU memory, "
      "with the time per stage.");
  bench->add_option("--scene", o->scene, "Scene YAML")
      ->check(CLI::ExistingFile)
      ->capture_default_str();
  bench->add_option("--frames", o->frames, "Frames to time")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  bench->add_option("--warmup", o->warmup, "Frames rendered before timing")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  AddRendererOptions(bench, &o->renderer);
  bench->add_flag("--json", o->json, "Print JSON");
  return [o] { return RunBench(*o); };
}

}  // namespace saccade::app
