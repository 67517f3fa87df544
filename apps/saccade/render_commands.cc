// render and bench: headless stereo capture to files, and the frames-per-second benchmark.

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <future>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "saccade/core/error.h"
#include "saccade/core/image_io.h"
#include "saccade/geometry/calibration_io.h"
#include "saccade/geometry/json.h"
#include "saccade/head/json.h"
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

json MatrixJson(const Eigen::Matrix4d& m) {
  json out = json::array();
  for (int r = 0; r < 4; ++r) out.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return out;
}

// --- ground truth ------------------------------------------------------------------------

/// What `render --truth` asked for.
struct TruthRequest {
  bool depth = false;
  bool ids = false;
  bool boxes = false;
  bool Any() const { return depth || ids || boxes; }
};

constexpr const char* kTruthItems = "depth, ids, boxes";
// 16-bit PNGs: depth in millimetres up to 65.535 m, ids up to 65535.
constexpr uint16_t kMaxPng16 = 65535;
constexpr double kMillimetresPerMetre = 1000.0;

/// "depth,ids,boxes" (any subset, any order) to a request. Throws InvalidArgument naming the
/// bad item and the valid ones.
TruthRequest ParseTruth(const std::string& list) {
  TruthRequest truth;
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    const std::string item = list.substr(begin, end - begin);
    if (item == "depth") {
      truth.depth = true;
    } else if (item == "ids") {
      truth.ids = true;
    } else if (item == "boxes") {
      truth.boxes = true;
    } else {
      throw InvalidArgument(
          item.empty()
              ? fmt::format("render: --truth '{}': an empty item; expected a comma-separated list "
                            "of {}",
                            list, kTruthItems)
              : fmt::format("render: --truth: unknown item '{}'; expected a comma-separated list "
                            "of {}",
                            item, kTruthItems));
    }
    begin = end + 1;
  }
  return truth;
}

/// The 16-bit id images hold ids up to 65535: refuses a scene with a larger id that the
/// images could show, naming it, before anything is rendered.
void CheckIdsFitPng16(const scene::Scene& scene, const render::RendererOptions& options) {
  const auto refuse = [](const std::string& owner, uint32_t id) {
    throw InvalidArgument(
        fmt::format("render: --truth ids: {} has instance id {}, and the id images are 16-bit PNGs "
                    "(ids up to {}); give it a smaller id in the scene",
                    owner, id, kMaxPng16));
  };
  for (const scene::Object& object : scene.objects()) {
    if (object.id > kMaxPng16) refuse("object '" + object.name + "'", object.id);
  }
  const auto& robot = scene.robot();
  if (robot && robot->visible && options.draw_robot && robot->id > kMaxPng16) {
    refuse("the robot", robot->id);
  }
}

/// A truth image of a frame, checked against what was asked for: a missing or malformed one
/// is the renderer's fault (saccade::Error), not the user's.
const Image& TruthImage(const std::shared_ptr<const Image>& image, const render::Frame& frame,
                        const char* what, PixelFormat format) {
  const std::string& camera = frame.color->metadata().camera;
  if (image == nullptr) {
    throw Error(fmt::format(
        "render: internal error: the renderer returned no {} image for camera {} although "
        "--truth asked for one",
        what, camera));
  }
  if (image->format() != format || image->width() != frame.color->width() ||
      image->height() != frame.color->height()) {
    throw Error(
        fmt::format("render: internal error: camera {}'s {} image is {} {}x{}, expected {} {}x{}",
                    camera, what, ToString(image->format()), image->width(), image->height(),
                    ToString(format), frame.color->width(), frame.color->height()));
  }
  return *image;
}

/// kFloat32 depth (metres) to kGray16 millimetres, rounded to nearest: 0 where there is no
/// surface, at least 1 where there is one, 65535 for 65.535 m and beyond.
Image DepthToMillimetres(const Image& depth) {
  Image out(depth.width(), depth.height(), PixelFormat::kGray16);
  for (int y = 0; y < depth.height(); ++y) {
    const uint8_t* in = depth.row(y);
    auto* row = reinterpret_cast<uint16_t*>(out.row(y));
    for (int x = 0; x < depth.width(); ++x) {
      float z = 0.0f;
      std::memcpy(&z, in + 4 * static_cast<std::size_t>(x), sizeof z);
      const double mm = std::round(static_cast<double>(z) * kMillimetresPerMetre);
      if (!(z > 0.0f)) {
        row[x] = 0;  // no surface (or not a number)
      } else if (mm >= kMaxPng16) {
        row[x] = kMaxPng16;
      } else {
        row[x] = std::max<uint16_t>(1, static_cast<uint16_t>(mm));  // 0 means no surface
      }
    }
  }
  return out;
}

/// kUint32 ids to kGray16. The scene's ids were checked to fit (CheckIdsFitPng16); a larger
/// one here is the renderer's fault.
Image IdsToPng16(const Image& ids, const std::string& camera) {
  Image out(ids.width(), ids.height(), PixelFormat::kGray16);
  uint32_t largest = 0;
  for (int y = 0; y < ids.height(); ++y) {
    const uint8_t* in = ids.row(y);
    auto* row = reinterpret_cast<uint16_t*>(out.row(y));
    for (int x = 0; x < ids.width(); ++x) {
      uint32_t id = 0;
      std::memcpy(&id, in + 4 * static_cast<std::size_t>(x), sizeof id);
      largest = std::max(largest, id);
      row[x] = static_cast<uint16_t>(id);
    }
  }
  if (largest > kMaxPng16) {
    throw Error(fmt::format("render: internal error: camera {}'s id image holds id {} (> {})",
                            camera, largest, kMaxPng16));
  }
  return out;
}

/// The objects seen in a frame (pixels > 0): id, name, 2D box, pixels and pose.
json ObjectsJson(const render::Frame& frame, bool scene_has_objects) {
  if (frame.objects.empty() && scene_has_objects) {
    throw Error(fmt::format(
        "render: internal error: the renderer returned no object truth for camera {} although "
        "--truth boxes asked for it",
        frame.color->metadata().camera));
  }
  json objects = json::array();
  for (const render::ObjectTruth& o : frame.objects) {
    if (o.pixels <= 0) continue;
    objects.push_back({{"id", o.id},
                       {"name", o.name},
                       {"box", {o.x_min, o.y_min, o.x_max, o.y_max}},
                       {"pixels", o.pixels},
                       {"X_CO", MatrixJson(o.X_CO)},
                       {"X_WO", MatrixJson(o.X_WO)}});
  }
  return objects;
}

std::string DepthFile(const std::string& camera, int64_t index) {
  return fmt::format("{}/depth/{:06d}.png", camera, index);
}
std::string IdsFile(const std::string& camera, int64_t index) {
  return fmt::format("{}/ids/{:06d}.png", camera, index);
}

/// One line of frames.jsonl: a frame index, its time and every camera's image and metadata.
json FrameJson(int64_t index, double time, const std::vector<render::Frame>& frames,
               const TruthRequest& truth, bool scene_has_objects) {
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
      entry["joints"] =
          ToJson(head::JointState{m.joints[0], m.joints[1], m.joints[2], m.joints[3]});
    }
    if (truth.depth) entry["depth"] = DepthFile(m.camera, index);
    if (truth.ids) entry["ids"] = IdsFile(m.camera, index);
    if (truth.boxes) entry["objects"] = ObjectsJson(frame, scene_has_objects);
    cameras[m.camera] = entry;
  }
  return {{"frame", index}, {"time", time}, {"cameras", cameras}};
}

/// The output folder: created if missing; one that already holds saccade output is refused
/// unless `force`, in which case the old output of these cameras is removed first.
void PrepareOutput(const fs::path& out, const std::vector<std::string>& cameras,
                   const TruthRequest& truth, bool force) {
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
  // Only our own frames: a camera folder holding anything else keeps it.
  const auto remove_frames = [](const fs::path& folder) {
    if (!fs::is_directory(folder)) return;
    for (const auto& entry : fs::directory_iterator(folder)) {
      if (entry.path().extension() == ".png") fs::remove(entry.path());
    }
  };
  for (const auto& path : existing) {
    if (fs::is_directory(path)) {
      remove_frames(path);
      for (const char* truth_folder : {"depth", "ids"}) {
        remove_frames(path / truth_folder);
        std::error_code ignored;
        fs::remove(path / truth_folder, ignored);  // only when left empty
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
  for (const auto& camera : cameras) {
    fs::create_directories(out / camera);
    if (truth.depth) fs::create_directories(out / camera / "depth");
    if (truth.ids) fs::create_directories(out / camera / "ids");
  }
}

/// The camera model a frame was rendered with: the camera's K and the distortion its metadata
/// says was rendered ("none" when RendererOptions::distortion was off or the lens has none).
geometry::CameraModel RenderedModel(const scene::CameraSpec& camera, const ImageMetadata& m) {
  geometry::DistortionModel model = geometry::DistortionModel::kNone;
  if (m.distortion_model == geometry::ToString(geometry::DistortionModel::kRadialTangential)) {
    model = geometry::DistortionModel::kRadialTangential;
  } else if (m.distortion_model == geometry::ToString(geometry::DistortionModel::kFisheye)) {
    model = geometry::DistortionModel::kFisheye;
  } else if (m.distortion_model != geometry::ToString(geometry::DistortionModel::kNone)) {
    throw Error(fmt::format("render: internal error: camera {}'s frame says distortion '{}'",
                            camera.name, m.distortion_model));
  }
  return geometry::CameraModel(camera.model.intrinsics(),
                               geometry::Distortion::FromCoefficients(model, m.distortion));
}

/// DIR/<camera>.yaml for every camera and DIR/stereo.yaml for a head's eyes, describing the
/// images as rendered (the first frames' metadata): K, and the lens distortion whenever it
/// was rendered.
void WriteCalibrations(const scene::Scene& scene, const scene::SceneState& state,
                       const std::vector<render::Frame>& frames, bool distortion_on,
                       const fs::path& out) {
  std::optional<geometry::CameraModel> left, right;
  for (const render::Frame& frame : frames) {
    const ImageMetadata& m = frame.color->metadata();
    const scene::CameraSpec* camera = scene.FindCamera(m.camera);
    if (camera == nullptr) {
      throw Error("render: internal error: a frame of unknown camera '" + m.camera + "'");
    }
    const geometry::CameraModel model = RenderedModel(*camera, m);
    if (distortion_on && !camera->model.distortion().IsIdentity() &&
        model.distortion().model() == geometry::DistortionModel::kNone) {
      // Only a renderer without lens effects does this; the files then say what the images are.
      fmt::print(stderr,
                 "warning: camera {}: the renderer did not apply its {} distortion; its images "
                 "and calibration file are pinhole (K only)\n",
                 m.camera, geometry::ToString(camera->model.distortion().model()));
    }
    geometry::WriteCameraCalibration({model, m.camera}, out / (m.camera + ".yaml"),
                                     geometry::CalibrationFormat::kOpenCvYaml);
    if (camera->mount == scene::CameraMount::kLeftEye) left = model;
    if (camera->mount == scene::CameraMount::kRightEye) right = model;
  }
  // The stereo pair's extrinsics at these joints (cv::stereoCalibrate's R, T).
  if (!left || !right) return;
  if (left->intrinsics().width() != right->intrinsics().width() ||
      left->intrinsics().height() != right->intrinsics().height()) {
    return;  // OpenCV's stereo files hold one image size
  }
  const geometry::Pose X_RL = scene.CameraPose(*scene.FindCamera("right"), state).inverse() *
                              scene.CameraPose(*scene.FindCamera("left"), state);
  geometry::StereoCalibration stereo{*left, *right, X_RL.linear(), X_RL.translation()};
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
  std::string truth;                          ///< --truth: "depth,ids,boxes" or a part of it
  const CLI::Option* truth_option = nullptr;  ///< whether --truth was given (even empty)
  render::RendererOptions renderer;           ///< --msaa, --lod-max-error, --no-distortion, ...
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

/// Writes one camera's images of frame i: colour, and depth and ids when asked for.
void WriteFrameImages(const render::Frame& frame, int i, const TruthRequest& truth,
                      const fs::path& out) {
  const std::string& camera = frame.color->metadata().camera;
  std::vector<std::future<void>> writes;
  writes.push_back(std::async(std::launch::async, [&] {
    WritePng(frame.color->view(), out / camera / fmt::format("{:06d}.png", i));
  }));
  if (truth.depth) {
    const Image& depth = TruthImage(frame.depth, frame, "depth", PixelFormat::kFloat32);
    writes.push_back(std::async(std::launch::async, [&] {
      WritePng(DepthToMillimetres(depth).view(), out / DepthFile(camera, i));
    }));
  }
  if (truth.ids) {
    const Image& ids = TruthImage(frame.ids, frame, "id", PixelFormat::kUint32);
    writes.push_back(std::async(std::launch::async, [&] {
      WritePng(IdsToPng16(ids, camera).view(), out / IdsFile(camera, i));
    }));
  }
  for (auto& w : writes) w.get();  // rethrows a write error
}

int RunRender(const RenderOptions& o) {
  const bool truth_given = o.truth_option != nullptr && o.truth_option->count() > 0;
  const TruthRequest truth = truth_given ? ParseTruth(o.truth) : TruthRequest{};
  const scene::Scene scene = scene::Scene::Load(o.scene);
  const scene::SceneState initial = StateFor(scene, o.joints, o.degrees);
  render::RendererOptions options = o.renderer;
  options.cameras = o.cameras;
  options.truth_depth = truth.depth;
  options.truth_ids = truth.ids || truth.boxes;  // the boxes come from the id image
  options.truth_objects = truth.boxes;
  if (truth.ids) CheckIdsFitPng16(scene, options);
  auto renderer = render::MakeRenderer(scene, options);
  const std::vector<std::string>& cameras = renderer->camera_names();
  const fs::path out(o.out);
  PrepareOutput(out, cameras, truth, o.force);
  const bool scene_has_objects = !scene.objects().empty();

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
    // The calibration files describe the images as rendered: the first frame says how.
    if (i == 0) WriteCalibrations(scene, initial, frames, options.distortion, out);
    // Checked first: a frame whose truth is missing fails before any of its images is written.
    for (const auto& frame : frames) {
      if (truth.depth) TruthImage(frame.depth, frame, "depth", PixelFormat::kFloat32);
      if (truth.ids) TruthImage(frame.ids, frame, "id", PixelFormat::kUint32);
    }
    const json line = FrameJson(i, state_at(i).time, frames, truth, scene_has_objects);
    std::vector<std::future<void>> writes;
    for (const auto& frame : frames) {
      writes.push_back(std::async(std::launch::async, [&out, &frame, &truth, i] {
        WriteFrameImages(frame, i, truth, out);
      }));
    }
    for (auto& w : writes) w.get();  // rethrows a write error
    // The index line comes last: a frame listed in frames.jsonl has all its images.
    index << line.dump() << "\n" << std::flush;
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

// --- bench -------------------------------------------------------------------------------

struct BenchOptions {
  std::string scene = ShippedFile("scenes/bench.yaml");
  // 60 frames time a run to a few per cent; the effect table's seven runs then take about a
  // minute on llvmpipe (motion blur draws the scene blur_samples times per frame).
  int frames = 60;
  int warmup = 10;
  render::RendererOptions renderer;  ///< --msaa, --lod-max-error, --no-distortion, ...
  bool json = false;
  bool effect_table = true;
};

// The head's pan rate while timing motion blur: fast enough that an exposure of a few
// milliseconds smears the image by pixels, so that the blur's sub-frames are really drawn.
constexpr double kBenchPanRate = 2.0;  // rad/s

/// One timed run: `frames` stereo frames after `warmup`, pipelined as `render` does.
struct Measurement {
  std::string device;
  std::vector<std::string> cameras;
  int frames = 0;
  double seconds = 0.0;
  int64_t pixels = 0;
  // Per frame, milliseconds (RenderStats).
  double update_ms = 0.0, draw_ms = 0.0, effects_ms = 0.0, readback_ms = 0.0;

  double fps() const { return frames / std::max(seconds, 1e-9); }
  double ms_per_frame() const { return 1000.0 * seconds / std::max(frames, 1); }
};

Measurement Measure(const scene::Scene& scene, const render::RendererOptions& options,
                    const head::JointState& joint_velocities, int frames, int warmup) {
  auto renderer = render::MakeRenderer(scene, options);
  scene::SceneState initial = scene.InitialState();
  initial.joint_velocities = joint_velocities;
  auto state_at = [&](int i) {
    scene::SceneState state = initial;
    state.time = i / 30.0;
    return state;
  };
  for (int i = 0; i < warmup; ++i) renderer->Render(state_at(i), i);
  const render::RenderStats before = renderer->stats();
  const ProgressBar progress(frames);
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
      progress.Update(i + 1, (i + 1) / s);
    }
  }
  m.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  progress.Finish();
  const render::RenderStats& after = renderer->stats();
  m.frames = frames;
  m.update_ms = (after.scene_update_ms - before.scene_update_ms) / frames;
  m.draw_ms = (after.draw_ms - before.draw_ms) / frames;
  m.effects_ms = (after.effects_ms - before.effects_ms) / frames;
  m.readback_ms = (after.readback_ms - before.readback_ms) / frames;
  m.device = renderer->DeviceDescription();
  m.cameras = renderer->camera_names();
  return m;
}

/// One row of the effect table: a run with one effect on (or all, or none).
struct EffectRun {
  const char* name;   ///< JSON key
  const char* label;  ///< text table
  render::RendererOptions options;
  bool moving = false;       ///< the head pans at kBenchPanRate during the exposure
  std::string unconfigured;  ///< why the scene gives this effect nothing to do; empty: run
  std::optional<Measurement> result;
};

/// The runs of the effect table, all on `base`'s other options (MSAA, LOD, cameras).
std::vector<EffectRun> EffectRuns(const scene::Scene& scene, const render::RendererOptions& base,
                                  const std::vector<std::string>& cameras) {
  bool has_distortion = false, has_noise = false, has_blur = false;
  for (const auto& name : cameras) {
    const scene::CameraSpec& camera = *scene.FindCamera(name);
    has_distortion = has_distortion || !camera.model.distortion().IsIdentity();
    has_noise = has_noise || camera.sensor.HasNoise();
    has_blur = has_blur || camera.sensor.HasBlur();
  }
  render::RendererOptions off = base;
  off.distortion = off.noise = off.motion_blur = false;
  off.truth_depth = off.truth_ids = off.truth_objects = false;
  render::RendererOptions distortion = off, noise = off, blur = off, truth = off, all = off;
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
  const auto add = [&runs](const char* name, const char* label,
                           const render::RendererOptions& options, bool moving,
                           std::string unconfigured) {
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

int RunBench(const BenchOptions& o) {
  const scene::Scene scene = scene::Scene::Load(o.scene);
  if (scene.cameras().empty()) throw InvalidArgument("bench: the scene has no cameras");
  // The first figure: the options as given, the head still.
  const Measurement main = Measure(scene, o.renderer, {}, o.frames, o.warmup);
  std::vector<EffectRun> runs;
  if (o.effect_table) {
    runs = EffectRuns(scene, o.renderer, main.cameras);
    const head::JointState panning{kBenchPanRate, 0.0, 0.0, 0.0};
    for (EffectRun& run : runs) {
      if (!run.unconfigured.empty()) continue;
      run.result = Measure(scene, run.options, run.moving ? panning : head::JointState{}, o.frames,
                           o.warmup);
    }
  }
  const double off_ms =
      !runs.empty() && runs.front().result ? runs.front().result->ms_per_frame() : 0.0;
  const auto& cameras = main.cameras;
  const auto* first = scene.FindCamera(cameras.front());
  if (o.json) {
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
    json out = {{"scene", o.scene},
                {"device", main.device},
                {"cameras", cameras},
                {"width", first->model.intrinsics().width()},
                {"height", first->model.intrinsics().height()},
                {"msaa", o.renderer.msaa_samples},
                {"lod_max_error_px", o.renderer.lod_max_error_px},
                {"distortion", o.renderer.distortion},
                {"noise", o.renderer.noise},
                {"motion_blur", o.renderer.motion_blur},
                {"frames", o.frames},
                {"seconds", main.seconds},
                {"frames_per_second", main.fps()},
                {"megapixels_per_second", main.pixels / main.seconds / 1e6},
                {"ms_per_frame",
                 {{"total", main.ms_per_frame()},
                  {"scene_update", main.update_ms},
                  {"draw", main.draw_ms},
                  {"effects", main.effects_ms},
                  {"readback", main.readback_ms}}},
                {"effects", effects}};
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  const auto on_off = [](bool on) { return on ? "on" : "off"; };
  fmt::print("scene    {}\ndevice   {}\n", o.scene, main.device);
  fmt::print(
      "cameras  {} x {}x{}, msaa {}, lod max error {} px; distortion {}, noise {}, motion blur "
      "{}\n",
      cameras.size(), first->model.intrinsics().width(), first->model.intrinsics().height(),
      o.renderer.msaa_samples, o.renderer.lod_max_error_px, on_off(o.renderer.distortion),
      on_off(o.renderer.noise), on_off(o.renderer.motion_blur));
  fmt::print(
      "{} frames ({} cameras each, pixels in CPU memory, head still) in {:.3f} s: {:.1f} "
      "frames/s, {:.1f} Mpixel/s\n",
      o.frames, cameras.size(), main.seconds, main.fps(), main.pixels / main.seconds / 1e6);
  fmt::print(
      "per frame: {:.2f} ms total; stages (CPU wall time, overlapping with the GPU):\n"
      "  scene update {:.2f} ms, draw {:.2f} ms, effects {:.2f} ms, readback {:.2f} ms\n",
      main.ms_per_frame(), main.update_ms, main.draw_ms, main.effects_ms, main.readback_ms);
  if (runs.empty()) return 0;
  fmt::print("\ncost of each effect ({} frames after {} warm-up each; effects off otherwise):\n",
             o.frames, o.warmup);
  fmt::print("  {:<26} {:>9} {:>10} {:>10}\n", "run", "frames/s", "ms/frame", "extra ms");
  for (const EffectRun& run : runs) {
    if (!run.result) {
      fmt::print("  {:<26} not run: {}\n", run.label, run.unconfigured);
    } else if (&run == &runs.front()) {
      fmt::print("  {:<26} {:>9.1f} {:>10.2f} {:>10}\n", run.label, run.result->fps(),
                 run.result->ms_per_frame(), "-");
    } else {
      fmt::print("  {:<26} {:>9.1f} {:>10.2f} {:>+10.2f}\n", run.label, run.result->fps(),
                 run.result->ms_per_frame(), run.result->ms_per_frame() - off_ms);
    }
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
      "No sensor noise (the scene's sensor: read_noise_dn, gain_dn_per_e)");
  command->add_flag_callback(
      "--no-blur", [options] { options->motion_blur = false; },
      "No motion blur (the scene's sensor: exposure, blur_samples): each frame an instant");
}

}  // namespace

Runner AddRenderCommand(CLI::App& app) {
  auto o = std::make_shared<RenderOptions>();
  auto* render = app.add_subcommand(
      "render",
      "Render a scene headless through its calibrated cameras (lens distortion, sensor noise "
      "and motion blur as the scene describes them): DIR/<camera>/<frame>.png, each camera's "
      "calibration as OpenCV YAML with the distortion that was rendered (DIR/<camera>.yaml, "
      "DIR/stereo.yaml for a head), and DIR/frames.jsonl with every frame's metadata. Ctrl-C "
      "stops after the frame in hand: only whole frames are left.");
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
  render->add_flag("--force", o->force, "Replace output already in --out");
  return [o] { return RunRender(*o); };
}

Runner AddBenchCommand(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  auto* bench = app.add_subcommand(
      "bench",
      "Stereo frames per second: every camera rendered and its pixels in CPU memory, with the "
      "time per stage; then the cost of each effect (lens distortion, sensor noise, motion blur "
      "with the head panning at 2 rad/s, ground truth, all of them), each run alone with the "
      "others off, against a run with all of them off. The effect switches below apply to the "
      "first figure; the table sets them itself.");
  bench->add_option("--scene", o->scene, "Scene YAML")
      ->check(CLI::ExistingFile)
      ->capture_default_str();
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
