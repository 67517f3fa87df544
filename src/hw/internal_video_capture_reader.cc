// Readers over cv::VideoCapture: video files, image sequences (CAP_IMAGES), V4L2 devices and
// GStreamer pipelines.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "internal_frame_reader.h"
#include "saccade/hw/hw_error.h"

namespace saccade::hw::internal {
namespace {

namespace fs = std::filesystem;

/// How a VideoCapture is (re)opened.
using Opener = std::function<bool(cv::VideoCapture*)>;

class VideoCaptureReader final : public FrameReader {
 public:
  /// `opener` opened `capture` already; it is called again by Rewind. `file_time`: the frames
  /// carry their own time (videos).
  VideoCaptureReader(std::string device, std::string what, Opener opener,
                     std::unique_ptr<cv::VideoCapture> capture, bool live, bool file_time,
                     bool grab_failure_is_end)
      : device_(std::move(device)),
        what_(std::move(what)),
        opener_(std::move(opener)),
        capture_(std::move(capture)),
        live_(live),
        file_time_(file_time),
        grab_failure_is_end_(grab_failure_is_end) {
    const double fps = capture_->get(cv::CAP_PROP_FPS);
    period_ = fps > 0.0 && std::isfinite(fps) ? 1.0 / fps : 0.0;
  }

  bool live() const override { return live_; }

  bool Latch() override {
    const bool grabbed = CallOpenCv(device_, what_, [&] { return capture_->grab(); });
    if (!grabbed) {
      if (grab_failure_is_end_) return false;
      throw HardwareError(device_, what_ + ": the device delivered no frame (grab failed)");
    }
    if (file_time_) {
      time_ = capture_->get(cv::CAP_PROP_POS_MSEC) / 1000.0;
    }
    return true;
  }

  cv::Mat Retrieve() override {
    cv::Mat frame;
    const bool ok = CallOpenCv(device_, what_, [&] { return capture_->retrieve(frame); });
    if (!ok || frame.empty()) {
      throw HardwareError(device_, what_ + ": cannot decode the frame (retrieve failed)");
    }
    return frame;
  }

  double FileTime() const override {
    return file_time_ ? time_ : std::numeric_limits<double>::quiet_NaN();
  }
  double FilePeriod() const override { return period_; }

  void Rewind() override {
    if (live_) return;
    capture_->release();
    if (!CallOpenCv(device_, what_, [&] { return opener_(capture_.get()); })) {
      throw HardwareError(device_, what_ + ": cannot open it again to loop");
    }
  }

 private:
  std::string device_;
  std::string what_;
  Opener opener_;
  std::unique_ptr<cv::VideoCapture> capture_;
  bool live_;
  bool file_time_;
  bool grab_failure_is_end_;
  double time_ = 0.0;
  double period_ = 0.0;
};

std::string BackendName(cv::VideoCaptureAPIs api) {
  return cv::videoio_registry::getBackendName(api);
}

bool FileExists(const fs::path& path, bool* is_directory) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  *is_directory = fs::is_directory(status);
  return fs::exists(status);
}

// Applies a device request; a property the device refuses is not an error here: the frame's
// size is checked against the calibration's, and the rate is the device's business.
void ApplyRequest(cv::VideoCapture* capture, const DeviceRequest& request) {
  if (request.width > 0 && request.height > 0) {
    capture->set(cv::CAP_PROP_FRAME_WIDTH, request.width);
    capture->set(cv::CAP_PROP_FRAME_HEIGHT, request.height);
  }
  if (request.fps > 0.0) capture->set(cv::CAP_PROP_FPS, request.fps);
}

}  // namespace

std::unique_ptr<FrameReader> OpenVideoFile(const std::string& device, const fs::path& path) {
  const std::string what = "video file " + path.string();
  bool is_directory = false;
  if (!FileExists(path, &is_directory)) throw HardwareError(device, what + ": file not found");
  if (is_directory) throw HardwareError(device, what + ": is a folder, expected a video file");
  // In order of preference; only the backends this OpenCV has. Not GStreamer: what it reads
  // FFmpeg reads on Debian, and a gstreamer: pipeline (filesrc ! decodebin ! ...) remains.
  std::vector<cv::VideoCaptureAPIs> apis;
  for (cv::VideoCaptureAPIs api : {cv::CAP_FFMPEG, cv::CAP_OPENCV_MJPEG}) {
    if (cv::videoio_registry::hasBackend(api)) apis.push_back(api);
  }
  std::string tried;
  auto capture = std::make_unique<cv::VideoCapture>();
  for (cv::VideoCaptureAPIs api : apis) {
    Opener opener = [path, api](cv::VideoCapture* c) { return c->open(path.string(), api); };
    bool opened = false;
    try {
      opened = opener(capture.get());
    } catch (const cv::Exception&) {
      opened = false;  // the next backend may read it
    }
    if (opened) {
      return std::make_unique<VideoCaptureReader>(device, what, std::move(opener),
                                                  std::move(capture), false, true, true);
    }
    tried += (tried.empty() ? "" : ", ") + BackendName(api);
  }
  throw HardwareError(device, what + ": not a video OpenCV can read (tried " +
                                  (tried.empty() ? std::string("no backend") : tried) + ")");
}

std::unique_ptr<FrameReader> OpenImageSequence(const std::string& device, const fs::path& pattern) {
  const std::string what = "image sequence " + pattern.string();
  const fs::path folder = pattern.has_parent_path() ? pattern.parent_path() : fs::path(".");
  bool is_directory = false;
  if (!FileExists(folder, &is_directory) || !is_directory) {
    throw HardwareError(device, what + ": folder " + folder.string() + " not found");
  }
  if (!cv::videoio_registry::hasBackend(cv::CAP_IMAGES)) {
    throw HardwareError(device, what + ": this OpenCV has no CAP_IMAGES backend");
  }
  Opener opener = [pattern](cv::VideoCapture* c) {
    return c->open(pattern.string(), cv::CAP_IMAGES);
  };
  auto capture = std::make_unique<cv::VideoCapture>();
  if (!CallOpenCv(device, what, [&] { return opener(capture.get()); })) {
    throw HardwareError(device, what +
                                    ": no image matches the pattern (the sequence must start "
                                    "at index 0 or 1)");
  }
  return std::make_unique<VideoCaptureReader>(device, what, std::move(opener), std::move(capture),
                                              false, false, true);
}

std::unique_ptr<FrameReader> OpenV4l2(const std::string& device, const std::string& target,
                                      const DeviceRequest& request) {
  const bool is_index = !target.empty() && target.size() <= 4 &&
                        std::all_of(target.begin(), target.end(),
                                    [](unsigned char c) { return std::isdigit(c) != 0; });
  const std::string path = is_index ? "/dev/video" + target : target;
  const std::string what = "V4L2 device " + path;
  if (!cv::videoio_registry::hasBackend(cv::CAP_V4L2)) {
    throw HardwareError(device, what + ": this OpenCV has no V4L2 backend");
  }
  bool is_directory = false;
  if (!FileExists(path, &is_directory)) {
    throw HardwareError(device, what + ": no such device (is the camera plugged in?)");
  }
  Opener opener = [path, is_index, target](cv::VideoCapture* c) {
    return is_index ? c->open(std::stoi(target), cv::CAP_V4L2) : c->open(path, cv::CAP_V4L2);
  };
  auto capture = std::make_unique<cv::VideoCapture>();
  if (!CallOpenCv(device, what, [&] { return opener(capture.get()); })) {
    throw HardwareError(device, what + ": cannot open it (busy, or not a video capture device)");
  }
  CallOpenCv(device, what, [&] {
    ApplyRequest(capture.get(), request);
    return 0;
  });
  return std::make_unique<VideoCaptureReader>(device, what, std::move(opener), std::move(capture),
                                              true, false, false);
}

std::unique_ptr<FrameReader> OpenGStreamer(const std::string& device, const std::string& pipeline) {
  const std::string what = "GStreamer pipeline '" + pipeline + "'";
  if (!cv::videoio_registry::hasBackend(cv::CAP_GSTREAMER)) {
    throw HardwareError(device, what + ": this OpenCV has no GStreamer backend");
  }
  if (pipeline.find("appsink") == std::string::npos) {
    throw HardwareError(device, what + ": expected a pipeline ending in appsink");
  }
  Opener opener = [pipeline](cv::VideoCapture* c) { return c->open(pipeline, cv::CAP_GSTREAMER); };
  auto capture = std::make_unique<cv::VideoCapture>();
  if (!CallOpenCv(device, what, [&] { return opener(capture.get()); })) {
    throw HardwareError(device, what +
                                    ": cannot start it (a missing element or a bad caps string: "
                                    "see OpenCV's GStreamer warnings)");
  }
  // A pipeline ends (end of stream, num-buffers): grab then fails, and the source ends.
  return std::make_unique<VideoCaptureReader>(device, what, std::move(opener), std::move(capture),
                                              true, false, true);
}

}  // namespace saccade::hw::internal
