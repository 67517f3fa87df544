#include "saccade/hw/camera_source.h"

#include <Eigen/Core>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <utility>

#include "internal_frame_reader.h"
#include "saccade/core/error.h"
#include "saccade/geometry/calibration_io.h"
#include "saccade/geometry/distortion.h"
#include "saccade/geometry/image_camera.h"
#include "saccade/geometry/intrinsics.h"
#include "saccade/hw/hw_error.h"

namespace saccade::hw {
namespace {

namespace fs = std::filesystem;

// Still images carry no time: without an fps they are this far apart (OpenCV's CAP_IMAGES
// reports 1 fps too).
constexpr double kStillImagePeriod = 1.0;

enum class UriKind { kV4l2, kGStreamer, kIidc, kList, kSequence, kStill, kVideo };

struct ParsedUri {
  UriKind kind = UriKind::kVideo;
  std::string target;  ///< device, pipeline, GUID or path (before base_dir)
};

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// A printf integer conversion (%d, %04d) outside "%%": CAP_IMAGES' pattern.
bool IsPrintfPattern(const std::string& path) {
  for (size_t i = 0; i < path.size(); ++i) {
    if (path[i] != '%') continue;
    size_t j = i + 1;
    if (j < path.size() && path[j] == '%') {
      i = j;
      continue;
    }
    while (j < path.size() && std::isdigit(static_cast<unsigned char>(path[j])) != 0) ++j;
    if (j < path.size() && path[j] == 'd') return true;
  }
  return false;
}

// Extensions of the still-image formats OpenCV's imgcodecs reads.
bool IsStillImage(const fs::path& path) {
  const std::string extension = Lower(path.extension().string());
  for (const char* still :
       {".png", ".jpg", ".jpeg", ".jpe",  ".bmp", ".dib", ".tif", ".tiff", ".pgm", ".ppm", ".pbm",
        ".pnm", ".pxm", ".pfm",  ".webp", ".jp2", ".exr", ".hdr", ".pic",  ".sr",  ".ras"}) {
    if (extension == still) return true;
  }
  return false;
}

ParsedUri ParseUri(const std::string& device, const std::string& uri) {
  std::string path = uri;
  const size_t colon = uri.find(':');
  if (colon != std::string::npos && colon > 0 &&
      std::isalpha(static_cast<unsigned char>(uri[0])) != 0 &&
      std::all_of(uri.begin(), uri.begin() + static_cast<std::ptrdiff_t>(colon), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '+' || c == '-' || c == '.';
      })) {
    const std::string scheme = Lower(uri.substr(0, colon));
    const std::string rest = uri.substr(colon + 1);
    auto require = [&](const char* expected) {
      if (rest.empty()) {
        throw HardwareError(
            device, "uri '" + uri + "': nothing after '" + scheme + ":'; expected " + expected);
      }
    };
    if (scheme == "v4l2") {
      require("a device (v4l2:/dev/video0 or v4l2:0)");
      return {UriKind::kV4l2, rest};
    }
    if (scheme == "gstreamer") {
      require("a pipeline ending in appsink");
      return {UriKind::kGStreamer, rest};
    }
    if (scheme == "iidc") {
      require("a GUID or a camera index (iidc:0)");
      return {UriKind::kIidc, rest};
    }
    if (scheme == "list") {
      require("an image list file");
      return {UriKind::kList, rest};
    }
    if (scheme != "file") {
      throw HardwareError(device, "uri '" + uri + "': unknown scheme '" + scheme +
                                      "'; expected v4l2:, gstreamer:, iidc:, list:, file: or a "
                                      "file path (a video, an image, a printf pattern such as "
                                      "frames/left_%04d.png)");
    }
    require("a file path");
    path = rest;
  }
  if (IsPrintfPattern(path)) return {UriKind::kSequence, path};
  if (IsStillImage(path)) return {UriKind::kStill, path};
  return {UriKind::kVideo, path};
}

fs::path Resolve(const std::string& base_dir, const std::string& path) {
  const fs::path p(path);
  if (p.is_absolute() || base_dir.empty()) return p;
  return fs::path(base_dir) / p;
}

std::string SizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

// What the simulator's cameras would be without a calibration: a pinhole whose focal length
// is the larger side (a 53 degree horizontal field for 4:3), centred, undistorted.
geometry::CameraModel NominalModel(int width, int height) {
  const double f = std::max(width, height);
  return geometry::CameraModel(
      geometry::Intrinsics(width, height, f, f, (width - 1) / 2.0, (height - 1) / 2.0));
}

std::string CalibrationMessage(const Error& e) { return std::string("calibration: ") + e.what(); }

class OpenedSource final : public CameraSource {
 public:
  OpenedSource(const CameraSourceSpec& spec, std::string device,
               std::unique_ptr<internal::FrameReader> reader)
      : CameraSource(spec.name, spec.uri, NominalModel(1, 1), false, reader->live()),
        device_(std::move(device)),
        reader_(std::move(reader)),
        fps_(spec.fps),
        loop_(spec.loop),
        first_(spec.first),
        every_(spec.every) {}

  /// Reads the first frame and sets the model from it and the calibration (if any).
  void Start(const fs::path& calibration, int calibration_index) {
    cv::Mat frame;
    if (live()) {
      if (!reader_->Latch()) throw HardwareError(device_, "the device delivered no frame");
      frame = reader_->Retrieve();  // a check and the size: a live frame goes stale, dropped
    } else {
      if (!NextFileFrame()) {
        throw HardwareError(device_, first_ > 0 ? "no frame after skipping the first " +
                                                      std::to_string(first_) + " (first)"
                                                : std::string("no frames"));
      }
      frame = reader_->Retrieve();
      pending_ = frame;
      pending_raw_time_ = last_raw_time_;
    }
    const int width = frame.cols;
    const int height = frame.rows;
    if (calibration.empty()) {
      set_model(NominalModel(width, height), false);
      return;
    }
    calibration_ = calibration.string();
    const geometry::ImageSize size{width, height};
    geometry::CameraModel model = NominalModel(1, 1);
    try {
      model =
          calibration_index == 0
              ? geometry::ReadCameraCalibration(calibration, size).model
              : geometry::ReadStereoCameraCalibration(calibration, calibration_index, size).model;
    } catch (const Error& e) {
      throw HardwareError(device_, CalibrationMessage(e));
    }
    const geometry::Intrinsics& intrinsics = model.intrinsics();
    if (intrinsics.width() != width || intrinsics.height() != height) {
      throw HardwareError(device_, "the first frame is " + SizeText(width, height) +
                                       " but the calibration " + calibration_ + " is for " +
                                       SizeText(intrinsics.width(), intrinsics.height()));
    }
    set_model(model, true);
  }

  std::shared_ptr<Image> Grab() override {
    if (!Latch()) return nullptr;
    return Retrieve();
  }

  bool Latch() override {
    latched_ = false;
    if (ended_) return false;
    if (live()) {
      if (!reader_->Latch()) {
        ended_ = true;
        return false;
      }
      latched_time_ =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - epoch()).count();
      latched_ = true;
      return true;
    }
    if (!pending_.empty() && from_pending_) {
      pending_.release();  // latched before and never retrieved: dropped
      from_pending_ = false;
    }
    if (!pending_.empty()) {
      from_pending_ = true;
      latched_raw_time_ = pending_raw_time_;
      latched_ = true;
      return true;
    }
    if (!NextFileFrame()) {
      ended_ = true;
      return false;
    }
    latched_raw_time_ = last_raw_time_ + loop_offset_;
    latched_ = true;
    return true;
  }

  std::shared_ptr<Image> Retrieve() override {
    if (!latched_) return nullptr;
    latched_ = false;
    cv::Mat frame;
    if (from_pending_) {
      frame = pending_;
      pending_.release();
      from_pending_ = false;
    } else {
      frame = reader_->Retrieve();
    }
    const int64_t index = next_index_;
    const geometry::Intrinsics& intrinsics = model().intrinsics();
    if (frame.cols != intrinsics.width() || frame.rows != intrinsics.height()) {
      throw HardwareError(
          device_, "frame " + std::to_string(index) + " is " + SizeText(frame.cols, frame.rows) +
                       " but " +
                       (calibrated() ? "the calibration " + calibration_ + " is for "
                                     : std::string("the first frame was ")) +
                       SizeText(intrinsics.width(), intrinsics.height()));
    }
    auto image = std::make_shared<Image>(frame.cols, frame.rows, PixelFormat::kRgb8);
    ToRgb(frame, index, image.get());
    ++next_index_;
    FillMetadata(index, image->metadata());
    return image;
  }

 private:
  // Latches the next frame of a file to deliver: skips `first` frames at the start and
  // every - 1 between deliveries; at the end, starts again when looping.
  bool NextFileFrame() {
    for (int pass = 0; pass < 2; ++pass) {
      const int skip = at_start_ ? first_ : every_ - 1;
      bool ok = true;
      for (int i = 0; i < skip && ok; ++i) ok = reader_->Latch();
      if (ok) ok = reader_->Latch();
      if (ok) {
        at_start_ = false;
        delivered_any_ = true;
        last_raw_time_ = reader_->FileTime();
        return true;
      }
      if (!loop_ || !delivered_any_) return false;
      // The next pass continues the time one frame period after the last frame.
      const double period = reader_->FilePeriod() > 0.0 ? reader_->FilePeriod() : 1.0;
      if (!std::isnan(last_raw_time_)) loop_offset_ += last_raw_time_ + period;
      reader_->Rewind();
      at_start_ = true;
    }
    return false;
  }

  double FrameTime(int64_t index) const {
    if (live()) return latched_time_;
    if (fps_ > 0.0) return static_cast<double>(index) / fps_;
    if (!std::isnan(latched_raw_time_)) return latched_raw_time_;
    return static_cast<double>(index) * kStillImagePeriod;
  }

  void ToRgb(const cv::Mat& frame, int64_t index, Image* image) const {
    cv::Mat source = frame;
    if (source.depth() == CV_16U) {
      source.convertTo(source, CV_8U, 1.0 / 256.0);
    } else if (source.depth() != CV_8U) {
      throw HardwareError(device_, "frame " + std::to_string(index) + " has OpenCV depth " +
                                       std::to_string(source.depth()) +
                                       ", expected 8 or 16 bits per channel");
    }
    cv::Mat rgb(image->height(), image->width(), CV_8UC3, image->data(), image->stride());
    int code = 0;
    switch (source.channels()) {
      case 1:
        code = cv::COLOR_GRAY2RGB;
        break;
      case 3:
        code = cv::COLOR_BGR2RGB;
        break;
      case 4:
        code = cv::COLOR_BGRA2RGB;
        break;
      default:
        throw HardwareError(device_, "frame " + std::to_string(index) + " has " +
                                         std::to_string(source.channels()) +
                                         " channels, expected 1, 3 or 4");
    }
    internal::CallOpenCv(device_, "frame " + std::to_string(index), [&] {
      cv::cvtColor(source, rgb, code);
      return 0;
    });
    SACCADE_ASSERT(rgb.data == image->data(), "cvtColor must write into the image's pixels");
  }

  void FillMetadata(int64_t index, ImageMetadata& meta) const {
    meta.camera = name();
    meta.frame_index = index;
    meta.time = FrameTime(index);
    if (!shared_model_ || !(*shared_model_ == model())) {
      shared_model_ = std::make_shared<const geometry::CameraModel>(model());
    }
    geometry::SetCameraModel(meta, shared_model_);
    // A camera alone: its optical frame is the world's (a head's cameras get their pose
    // from its kinematics, components/hw_cameras.cc).
    geometry::SetCameraPose(meta, geometry::Pose::Identity());
    meta.has_joints = false;
    meta.joints = {};
  }

  std::string device_;
  std::unique_ptr<internal::FrameReader> reader_;
  double fps_;
  bool loop_;
  int first_;
  int every_;
  std::string calibration_;
  // The frames' camera model, shared by every frame until the model changes (FillMetadata).
  mutable std::shared_ptr<const geometry::CameraModel> shared_model_;

  int64_t next_index_ = 0;
  bool ended_ = false;
  bool latched_ = false;
  double latched_time_ = 0.0;      ///< live: seconds since the epoch
  double latched_raw_time_ = 0.0;  ///< files: the file's own time, looping included (NaN: none)
  // Files.
  cv::Mat pending_;  ///< the first frame, read by Start
  double pending_raw_time_ = 0.0;
  bool from_pending_ = false;
  bool at_start_ = true;
  bool delivered_any_ = false;
  double last_raw_time_ = 0.0;  ///< the file's own time of the last frame latched (NaN: none)
  double loop_offset_ = 0.0;    ///< added to the file's time: the length of the passes before
};

}  // namespace

bool CameraSourceSpec::IsValid(std::string* error) const {
  std::string why;
  if (name.empty()) {
    why = "name: expected a camera name, got an empty string";
  } else if (uri.empty()) {
    why =
        "uri: expected a source (v4l2:/dev/video0, a video, an image list, ...), got an empty "
        "string";
  } else if (calibration_index < 0 || calibration_index > 2) {
    why = "calibration_index: expected 0 (a one-camera file), 1 (M1 D1) or 2 (M2 D2), got " +
          std::to_string(calibration_index);
  } else if (calibration_index != 0 && calibration.empty()) {
    why = "calibration_index: " + std::to_string(calibration_index) +
          " selects a camera of a stereo calibration file, but no calibration is given";
  } else if (!std::isfinite(fps) || fps < 0.0) {
    why = "fps: expected a frame rate >= 0 (0: none), got " + std::to_string(fps);
  } else if (first < 0) {
    why = "first: expected a frame index >= 0, got " + std::to_string(first);
  } else if (every < 1) {
    why = "every: expected a step >= 1, got " + std::to_string(every);
  }
  if (error != nullptr) *error = why;
  return why.empty();
}

CameraSource::CameraSource(std::string name, std::string uri, const geometry::CameraModel& model,
                           bool calibrated, bool live)
    : name_(std::move(name)),
      uri_(std::move(uri)),
      model_(model),
      calibrated_(calibrated),
      live_(live) {}

CameraSource::~CameraSource() = default;

bool CameraSource::Latch() {
  latched_ = Grab();
  return latched_ != nullptr;
}

std::shared_ptr<Image> CameraSource::Retrieve() { return std::move(latched_); }

std::unique_ptr<CameraSource> OpenCameraSource(const CameraSourceSpec& spec) {
  std::string why;
  if (!spec.IsValid(&why)) {
    throw InvalidArgument("OpenCameraSource: camera '" + spec.name + "': " + why);
  }
  const std::string device = "camera " + spec.name + " (" + spec.uri + ")";
  const ParsedUri uri = ParseUri(device, spec.uri);
  const bool live =
      uri.kind == UriKind::kV4l2 || uri.kind == UriKind::kGStreamer || uri.kind == UriKind::kIidc;
  if (live && (spec.first != 0 || spec.every != 1)) {
    throw InvalidArgument("OpenCameraSource: camera '" + spec.name +
                          "': first and every select frames of files, sequences and lists, not "
                          "of a device; got first " +
                          std::to_string(spec.first) + ", every " + std::to_string(spec.every));
  }
  fs::path calibration;
  internal::DeviceRequest request;
  request.fps = spec.fps;
  if (!spec.calibration.empty()) {
    calibration = Resolve(spec.base_dir, spec.calibration);
    try {
      if (const auto size = geometry::ReadCalibrationImageSize(calibration)) {
        request.width = size->width;
        request.height = size->height;
      }
    } catch (const Error& e) {
      throw HardwareError(device, CalibrationMessage(e));
    }
  }
  std::unique_ptr<internal::FrameReader> reader;
  switch (uri.kind) {
    case UriKind::kV4l2:
      reader = internal::OpenV4l2(device, uri.target, request);
      break;
    case UriKind::kGStreamer:
      reader = internal::OpenGStreamer(device, uri.target);
      break;
    case UriKind::kIidc:
      reader = internal::OpenIidc(device, uri.target, request);
      break;
    case UriKind::kList:
      reader = internal::OpenImageList(device, Resolve(spec.base_dir, uri.target));
      break;
    case UriKind::kSequence:
      reader = internal::OpenImageSequence(device, Resolve(spec.base_dir, uri.target));
      break;
    case UriKind::kStill:
      reader = internal::OpenStillImage(device, Resolve(spec.base_dir, uri.target));
      break;
    case UriKind::kVideo:
      reader = internal::OpenVideoFile(device, Resolve(spec.base_dir, uri.target));
      break;
  }
  auto source = std::make_unique<OpenedSource>(spec, device, std::move(reader));
  source->Start(calibration, spec.calibration_index);
  return source;
}

bool IidcSupported() { return internal::HaveIidc(); }

}  // namespace saccade::hw
