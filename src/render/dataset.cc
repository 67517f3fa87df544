#include "saccade/render/dataset.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <future>
#include <optional>
#include <string>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/core/image_io.h"
#include "saccade/core/log.h"
#include "saccade/core/temporary_file.h"
#include "saccade/geometry/calibration_io.h"
#include "saccade/geometry/image_camera.h"
#include "saccade/geometry/json.h"
#include "saccade/head/json.h"
#include "saccade/render/color_filter.h"

namespace saccade::render {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr const char* kTruthItems = "depth, ids, boxes";
// 16-bit PNGs: depth in millimetres up to 65.535 m, ids up to 65535.
constexpr uint16_t kMaxPng16 = 65535;
constexpr double kMillimetresPerMetre = 1000.0;

/// A truth image of a frame, checked against what was asked for: a missing or malformed one
/// is the renderer's fault (saccade::Error), not the user's.
const Image& TruthImage(const std::shared_ptr<const Image>& image, const Frame& frame,
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

}  // namespace

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

namespace {

/// The objects seen in a frame (pixels > 0): id, name, 2D box, pixels and pose.
json ObjectsJson(const Frame& frame, bool scene_has_objects) {
  if (frame.objects.empty() && scene_has_objects) {
    throw Error(fmt::format(
        "render: internal error: the renderer returned no object truth for camera {} although "
        "--truth boxes asked for it",
        frame.color->metadata().camera));
  }
  json objects = json::array();
  for (const ObjectTruth& o : frame.objects) {
    if (o.pixels <= 0) continue;
    objects.push_back({{"id", o.id},
                       {"name", o.name},
                       {"box", {o.x_min, o.y_min, o.x_max, o.y_max}},
                       {"pixels", o.pixels},
                       {"X_CO", ToJson(geometry::Pose(o.X_CO))},
                       {"X_WO", ToJson(geometry::Pose(o.X_WO))}});
  }
  return objects;
}

std::string DepthFile(const std::string& camera, int64_t index) {
  return fmt::format("{}/depth/{:06d}.png", camera, index);
}
std::string IdsFile(const std::string& camera, int64_t index) {
  return fmt::format("{}/ids/{:06d}.png", camera, index);
}
std::string RawFile(const std::string& camera, int64_t index) {
  return fmt::format("{}/raw/{:06d}.png", camera, index);
}

/// The camera model a frame was rendered with (it carries it: geometry/image_camera.h).
const geometry::CameraModel& RenderedModel(const ImageMetadata& m) {
  const geometry::CameraModel* model = geometry::FindCameraModel(m);
  if (model == nullptr) {
    throw Error("render: internal error: camera " + m.camera + "'s frame carries no camera model");
  }
  return *model;
}

/// One line of frames.jsonl: a frame index, its time and every camera's image and metadata.
}  // namespace

json FrameRecord(int64_t index, double time, const std::vector<Frame>& frames,
                 const TruthRequest& truth, bool scene_has_objects, bool files) {
  json cameras = json::object();
  for (const auto& frame : frames) {
    const ImageMetadata& m = frame.color->metadata();
    // The camera model's codec (geometry/json.h): width, height, K, distortion.
    json entry = ToJson(RenderedModel(m));
    if (files) entry["file"] = fmt::format("{}/{:06d}.png", m.camera, index);
    // Poses in geometry/json.h's one form, as everywhere else (4x4 nested, row by row).
    entry["X_WC"] = ToJson(*geometry::FindCameraPose(m));
    entry["exposure_samples"] = m.exposure_samples;
    // The camera controls the frame was taken with (scene/camera_controls.h).
    entry["exposure_s"] = m.exposure_s;
    entry["gain_db"] = m.gain_db;
    entry["focus_m"] = m.focus_m;
    if (m.has_joints) {
      json joints = json::object();
      for (size_t i = 0; i < m.joints.size() && m.joint_names; ++i) {
        joints[(*m.joint_names)[i]] = m.joints[i];
      }
      entry["joints"] = joints;
    }
    if (frame.raw) {
      // The raw mosaic (RendererOptions::color with a filter array): 8-bit, one sample a pixel.
      entry["cfa"] = ToString(PatternOf(frame.raw->format()));
      if (files) entry["raw"] = RawFile(m.camera, index);
    }
    if (truth.depth && files) entry["depth"] = DepthFile(m.camera, index);
    if (truth.ids && files) entry["ids"] = IdsFile(m.camera, index);
    if (truth.boxes) entry["objects"] = ObjectsJson(frame, scene_has_objects);
    cameras[m.camera] = entry;
  }
  return {{"frame", index}, {"time", time}, {"cameras", cameras}};
}

namespace {

/// The output folder: created if missing; one that already holds saccade output is refused
/// unless `force`, in which case the old output of these cameras is removed first. Either way
/// the hidden temporaries a killed run left there (".000012.png.tmp4242_7", core/
/// temporary_file.h) go too; no other file is touched.
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
  // A run killed mid-write (SIGKILL) leaves its temporaries beside the frames and calibrations.
  int stale = RemoveStaleTemporaries(out);
  for (const auto& camera : cameras) {
    stale += RemoveStaleTemporaries(out / camera);
    for (const char* truth_folder : {"depth", "ids", "raw"}) {
      stale += RemoveStaleTemporaries(out / camera / truth_folder);
    }
  }
  if (stale > 0) {
    log::Info("render: removed {} temporary files an interrupted run left in {}", stale,
              out.string());
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
      for (const char* truth_folder : {"depth", "ids", "raw"}) {
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

/// DIR/<camera>.yaml for every camera and DIR/stereo.yaml for a head's eyes, describing the
/// images as rendered (the first frames' metadata): K, and the lens distortion whenever it
/// was rendered.
void WriteCalibrations(const scene::Scene& scene, const scene::SceneState& state,
                       const std::vector<Frame>& frames, bool distortion_on, const fs::path& out) {
  std::optional<geometry::CameraModel> left, right;
  for (const Frame& frame : frames) {
    const ImageMetadata& m = frame.color->metadata();
    const scene::CameraSpec* camera = scene.FindCamera(m.camera);
    if (camera == nullptr) {
      throw Error("render: internal error: a frame of unknown camera '" + m.camera + "'");
    }
    const geometry::CameraModel& model = RenderedModel(m);
    if (distortion_on && !camera->model.distortion().IsIdentity() &&
        model.distortion().model() == geometry::DistortionModel::kNone) {
      // Only a renderer without lens effects does this; the files then say what the images are.
      log::Warn(
          "camera {}: the renderer did not apply its {} distortion; its images and calibration "
          "file are pinhole (K only)",
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

/// Writes one camera's images of frame i: colour, and depth and ids when asked for.
void WriteFrameImages(const Frame& frame, int i, const TruthRequest& truth, const fs::path& out) {
  const std::string& camera = frame.color->metadata().camera;
  std::vector<std::future<void>> writes;
  writes.push_back(std::async(std::launch::async, [&] {
    WritePng(frame.color->view(), out / camera / fmt::format("{:06d}.png", i));
  }));
  if (frame.raw) {
    writes.push_back(std::async(std::launch::async, [&] {
      const Image& raw = *frame.raw;
      fs::create_directories(out / camera / "raw");
      // The mosaic's bytes as an 8-bit grey image: its pattern is in frames.jsonl ("cfa").
      const ImageView gray{raw.data(),          raw.width(),  raw.height(),
                           PixelFormat::kGray8, raw.stride(), &raw.metadata()};
      WritePng(gray, out / RawFile(camera, i));
    }));
  }
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

}  // namespace

TruthRequest TruthRequest::Parse(const std::string& list) {
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

void CheckIdsFitPng16(const scene::Scene& scene, const RendererOptions& options) {
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

void ApplyTruth(const TruthRequest& truth, RendererOptions* options) {
  options->truth_depth = truth.depth;
  options->truth_ids = truth.ids || truth.boxes;  // the boxes come from the id image
  options->truth_objects = truth.boxes;
}

DatasetWriter::DatasetWriter(const scene::Scene& scene, std::vector<std::string> cameras,
                             const TruthRequest& truth, std::filesystem::path out, bool force,
                             bool distortion_on)
    : scene_(scene),
      cameras_(std::move(cameras)),
      truth_(truth),
      out_(std::move(out)),
      distortion_on_(distortion_on),
      scene_has_objects_(!scene.objects().empty()) {
  PrepareOutput(out_, cameras_, truth_, force);
  index_.open(out_ / "frames.jsonl");
  if (!index_) throw FileError((out_ / "frames.jsonl").string(), 0, "", "cannot write");
}

void DatasetWriter::Write(int64_t index, double time, const scene::SceneState& state,
                          const std::vector<Frame>& frames) {
  // The calibration files describe the images as rendered: the first frame says how.
  if (written_ == 0) WriteCalibrations(scene_, state, frames, distortion_on_, out_);
  // Checked first: a frame whose truth is missing fails before any of its images is written.
  for (const auto& frame : frames) {
    if (truth_.depth) TruthImage(frame.depth, frame, "depth", PixelFormat::kFloat32);
    if (truth_.ids) TruthImage(frame.ids, frame, "id", PixelFormat::kUint32);
  }
  const json line = FrameRecord(index, time, frames, truth_, scene_has_objects_, true);
  std::vector<std::future<void>> writes;
  const int i = static_cast<int>(index);
  for (const auto& frame : frames) {
    writes.push_back(std::async(std::launch::async,
                                [this, &frame, i] { WriteFrameImages(frame, i, truth_, out_); }));
  }
  for (auto& w : writes) w.get();  // rethrows a write error
  // The index line comes last: a frame listed in frames.jsonl has all its images.
  index_ << line.dump() << "\n" << std::flush;
  ++written_;
}

int RenderDataset(Renderer& renderer, FrameSink& sink, const scene::SceneState& initial, int frames,
                  double fps, const std::atomic<bool>& stop,
                  const std::function<void(int done, double fps)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  const auto state_at = [&](int i) {
    scene::SceneState state = initial;
    state.time = i / fps;
    return state;
  };
  int written = 0;
  renderer.Submit(state_at(0), 0);
  for (int i = 0; i < frames && !stop; ++i) {
    if (i + 1 < frames) renderer.Submit(state_at(i + 1), i + 1);
    sink.Write(i, state_at(i).time, initial, renderer.Retrieve());
    ++written;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (progress) progress(written, written / std::max(seconds, 1e-9));
  }
  return written;
}

}  // namespace saccade::render
