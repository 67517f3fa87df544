#pragma once
// Private to camera_source.cc: the backends of a CameraSource. A reader delivers raw frames
// as cv::Mat; CameraSource converts them to RGB Images, stamps and checks them. Every error
// is a HardwareError whose device is the string given to the factory ("camera left (uri)").

#include <filesystem>
#include <limits>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "saccade/hw/hw_error.h"

namespace saccade::hw::internal {

/// A source of raw frames: a file, a sequence, a list or a device.
class FrameReader {
 public:
  virtual ~FrameReader() = default;

  /// True for devices: frames are stamped with the steady clock when latched; false for files.
  virtual bool live() const = 0;
  /// Takes the next frame without decoding it where the backend allows; false at the end of
  /// a file, sequence or list (or of a GStreamer stream). Throws HardwareError when a device
  /// fails.
  virtual bool Latch() = 0;
  /// The latched frame: 8- or 16-bit, 1 (gray), 3 (BGR) or 4 (BGRA) channels. Throws
  /// HardwareError when it cannot be decoded.
  virtual cv::Mat Retrieve() = 0;
  /// The latched frame's own time in seconds (a video's CAP_PROP_POS_MSEC); NaN when the
  /// frames carry none (still images, devices).
  virtual double FileTime() const { return std::numeric_limits<double>::quiet_NaN(); }
  /// The nominal frame period of a file in seconds (1 / its frame rate), 0 when unknown.
  virtual double FilePeriod() const { return 0.0; }
  /// Back to the first frame (loop). Files only; throws HardwareError when it cannot.
  virtual void Rewind() = 0;
};

/// What a device is asked for before its first frame; 0: the device's default.
struct DeviceRequest {
  int width = 0;
  int height = 0;
  double fps = 0.0;
};

/// A video file through OpenCV (FFmpeg, else OpenCV's MJPEG reader).
std::unique_ptr<FrameReader> OpenVideoFile(const std::string& device,
                                           const std::filesystem::path& path);
/// A printf-pattern image sequence (CAP_IMAGES).
std::unique_ptr<FrameReader> OpenImageSequence(const std::string& device,
                                               const std::filesystem::path& pattern);
/// A V4L2 device by path ("/dev/video0") or, when `target` is all digits, by index.
std::unique_ptr<FrameReader> OpenV4l2(const std::string& device, const std::string& target,
                                      const DeviceRequest& request);
/// A GStreamer pipeline ending in appsink (CAP_GSTREAMER). Its size and rate are set by the
/// pipeline's caps.
std::unique_ptr<FrameReader> OpenGStreamer(const std::string& device, const std::string& pipeline);
/// An image list file (FileStorage `imagelist`, or one path per line).
std::unique_ptr<FrameReader> OpenImageList(const std::string& device,
                                           const std::filesystem::path& list);
/// One still image.
std::unique_ptr<FrameReader> OpenStillImage(const std::string& device,
                                            const std::filesystem::path& path);
/// An IIDC camera by GUID or bus index through libdc1394 (internal_iidc_reader.cc); throws
/// HardwareError in builds without libdc1394.
std::unique_ptr<FrameReader> OpenIidc(const std::string& device, const std::string& id,
                                      const DeviceRequest& request);
/// Whether OpenIidc is built with libdc1394.
bool HaveIidc();

/// Calls `f`, turning a cv::Exception into a HardwareError(device, what + ": OpenCV: ...").
template <typename F>
auto CallOpenCv(const std::string& device, const std::string& what, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const cv::Exception& e) {
    throw HardwareError(device, what + ": OpenCV: " + e.msg);
  }
}

}  // namespace saccade::hw::internal
