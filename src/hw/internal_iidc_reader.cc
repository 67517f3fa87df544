// IIDC cameras (IEEE 1394 FireWire, USB IIDC) through libdc1394, such as the Point Grey Flea2
// of the POPEYE head. Built with libdc1394 when CMake finds it (SACCADE_HAVE_DC1394); without
// it, OpenIidc says so.

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "internal_frame_reader.h"
#include "saccade/hw/hw_error.h"

#ifdef SACCADE_HAVE_DC1394
#include <dc1394/dc1394.h>

#include <cinttypes>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#endif

namespace saccade::hw::internal {
namespace {

/// A camera asked for by GUID or by its index on the bus.
struct IidcId {
  bool by_index = false;
  uint64_t guid = 0;
  unsigned index = 0;
};

// "0", "1": an index; "0x00b09d0100a01a9a", "00b09d0100a01a9a": a GUID (more than 4 digits).
IidcId ParseIidcId(const std::string& device, const std::string& text) {
  auto all = [](std::string_view s, auto predicate) {
    if (s.empty()) return false;
    for (char c : s) {
      if (!predicate(static_cast<unsigned char>(c))) return false;
    }
    return true;
  };
  const auto is_digit = [](unsigned char c) { return std::isdigit(c) != 0; };
  const auto is_hex = [](unsigned char c) { return std::isxdigit(c) != 0; };
  const bool prefixed = text.starts_with("0x") || text.starts_with("0X");
  const std::string_view hex = prefixed ? std::string_view(text).substr(2) : std::string_view(text);
  IidcId id;
  if (!prefixed && text.size() <= 4 && all(text, is_digit)) {
    id.by_index = true;
    id.index = static_cast<unsigned>(std::stoul(text));
  } else if ((prefixed || text.size() > 4) && hex.size() <= 16 && all(hex, is_hex)) {
    id.guid = std::stoull(std::string(hex), nullptr, 16);
  } else {
    throw HardwareError(device, "IIDC camera '" + text +
                                    "': expected a GUID in hex (0x00b09d0100a01a9a) or a camera "
                                    "index (0, 1, ...)");
  }
  return id;
}

#ifdef SACCADE_HAVE_DC1394

std::string GuidText(uint64_t guid) {
  char text[24];
  std::snprintf(text, sizeof(text), "%016" PRIx64, guid);
  return text;
}

std::string Dc1394Error(dc1394error_t error) {
  const char* text = dc1394_error_get_string(error);
  return text != nullptr ? text : "error " + std::to_string(static_cast<int>(error));
}

/// The library context, the camera and its capture, released in reverse order.
class IidcCamera {
 public:
  IidcCamera() = default;
  IidcCamera(const IidcCamera&) = delete;
  IidcCamera& operator=(const IidcCamera&) = delete;
  ~IidcCamera() {
    if (camera_ != nullptr) {
      if (transmitting_) dc1394_video_set_transmission(camera_, DC1394_OFF);
      if (capturing_) dc1394_capture_stop(camera_);
      dc1394_camera_free(camera_);
    }
    if (context_ != nullptr) dc1394_free(context_);
  }

  dc1394_t* context_ = nullptr;
  dc1394camera_t* camera_ = nullptr;
  bool capturing_ = false;
  bool transmitting_ = false;
};

class IidcReader final : public FrameReader {
 public:
  IidcReader(std::string device, std::string what, std::unique_ptr<IidcCamera> camera)
      : device_(std::move(device)), what_(std::move(what)), camera_(std::move(camera)) {}
  ~IidcReader() override { Release(); }

  bool live() const override { return true; }

  bool Latch() override {
    Release();
    dc1394video_frame_t* frame = nullptr;
    const dc1394error_t error =
        dc1394_capture_dequeue(camera_->camera_, DC1394_CAPTURE_POLICY_WAIT, &frame);
    if (error != DC1394_SUCCESS || frame == nullptr) {
      throw HardwareError(device_, what_ + ": capture failed: " + Dc1394Error(error));
    }
    // The ring buffer hands out its oldest frame: take the newest one there, so that a slow
    // reader sees what the camera sees now rather than what it saw buffers ago.
    for (;;) {
      dc1394video_frame_t* newer = nullptr;
      if (dc1394_capture_dequeue(camera_->camera_, DC1394_CAPTURE_POLICY_POLL, &newer) !=
              DC1394_SUCCESS ||
          newer == nullptr) {
        break;
      }
      dc1394_capture_enqueue(camera_->camera_, frame);
      frame = newer;
    }
    frame_ = frame;
    if (dc1394_capture_is_frame_corrupt(camera_->camera_, frame_) == DC1394_TRUE) {
      Release();
      throw HardwareError(device_, what_ + ": the camera delivered a corrupt frame");
    }
    return true;
  }

  cv::Mat Retrieve() override {
    if (frame_ == nullptr) throw HardwareError(device_, what_ + ": no frame latched");
    cv::Mat out = Convert(*frame_);
    Release();
    return out;
  }

  void Rewind() override {}

 private:
  // The frame as gray, BGR or 16-bit gray, copied out of the DMA ring buffer.
  cv::Mat Convert(const dc1394video_frame_t& f) const {
    const int width = static_cast<int>(f.size[0]);
    const int height = static_cast<int>(f.size[1]);
    uint8_t* data = f.image;
    cv::Mat out;
    switch (f.color_coding) {
      case DC1394_COLOR_CODING_MONO8:
        return cv::Mat(height, width, CV_8UC1, data, f.stride).clone();
      case DC1394_COLOR_CODING_RAW8:
        if (f.color_filter >= DC1394_COLOR_FILTER_MIN &&
            f.color_filter <= DC1394_COLOR_FILTER_MAX) {
          cv::Mat rgb(height, width, CV_8UC3);
          dc1394_bayer_decoding_8bit(data, rgb.data, f.size[0], f.size[1], f.color_filter,
                                     DC1394_BAYER_METHOD_BILINEAR);
          cv::cvtColor(rgb, out, cv::COLOR_RGB2BGR);
          return out;
        }
        // No colour filter reported: the raw sensor values, as gray.
        return cv::Mat(height, width, CV_8UC1, data, f.stride).clone();
      case DC1394_COLOR_CODING_RGB8:
        cv::cvtColor(cv::Mat(height, width, CV_8UC3, data, f.stride), out, cv::COLOR_RGB2BGR);
        return out;
      case DC1394_COLOR_CODING_YUV411:
      case DC1394_COLOR_CODING_YUV422:
      case DC1394_COLOR_CODING_YUV444: {
        cv::Mat rgb(height, width, CV_8UC3);
        const dc1394error_t error = dc1394_convert_to_RGB8(
            data, rgb.data, f.size[0], f.size[1], f.yuv_byte_order, f.color_coding, f.data_depth);
        if (error != DC1394_SUCCESS) {
          throw HardwareError(device_, what_ + ": YUV conversion failed: " + Dc1394Error(error));
        }
        cv::cvtColor(rgb, out, cv::COLOR_RGB2BGR);
        return out;
      }
      case DC1394_COLOR_CODING_MONO16: {
        out = cv::Mat(height, width, CV_16UC1, data, f.stride).clone();
        if (f.little_endian != DC1394_TRUE) {
          for (int y = 0; y < height; ++y) {
            auto* row = out.ptr<uint16_t>(y);
            for (int x = 0; x < width; ++x) {
              row[x] = static_cast<uint16_t>((row[x] >> 8) | (row[x] << 8));
            }
          }
        }
        // data_depth significant bits: scale to the full 16-bit range.
        if (f.data_depth > 0 && f.data_depth < 16) {
          out *= static_cast<double>(1 << (16 - f.data_depth));
        }
        return out;
      }
      default:
        throw HardwareError(device_, what_ + ": colour coding " +
                                         std::to_string(static_cast<int>(f.color_coding)) +
                                         " is not supported (mono8, raw8, rgb8, yuv, mono16 are)");
    }
  }

  void Release() {
    if (frame_ != nullptr) {
      dc1394_capture_enqueue(camera_->camera_, frame_);
      frame_ = nullptr;
    }
  }

  std::string device_;
  std::string what_;
  std::unique_ptr<IidcCamera> camera_;
  dc1394video_frame_t* frame_ = nullptr;
};

// The closest frame rate the mode has to `fps`.
void SetFrameRate(const std::string& device, const std::string& what, dc1394camera_t* camera,
                  dc1394video_mode_t mode, double fps) {
  if (dc1394_is_video_mode_scalable(mode) == DC1394_TRUE) return;  // Format7: set by packet size
  dc1394framerates_t rates;
  if (dc1394_video_get_supported_framerates(camera, mode, &rates) != DC1394_SUCCESS ||
      rates.num == 0) {
    return;
  }
  dc1394framerate_t best = rates.framerates[0];
  double best_error = std::numeric_limits<double>::infinity();
  for (uint32_t i = 0; i < rates.num; ++i) {
    float value = 0.0F;
    if (dc1394_framerate_as_float(rates.framerates[i], &value) != DC1394_SUCCESS) continue;
    const double error = std::abs(value - fps);
    if (error < best_error) {
      best_error = error;
      best = rates.framerates[i];
    }
  }
  const dc1394error_t error = dc1394_video_set_framerate(camera, best);
  if (error != DC1394_SUCCESS) {
    throw HardwareError(device, what + ": cannot set the frame rate: " + Dc1394Error(error));
  }
}

#endif  // SACCADE_HAVE_DC1394

}  // namespace

#ifdef SACCADE_HAVE_DC1394

bool HaveIidc() { return true; }

std::unique_ptr<FrameReader> OpenIidc(const std::string& device, const std::string& id_text,
                                      const DeviceRequest& request) {
  const IidcId id = ParseIidcId(device, id_text);
  const std::string looking_for =
      id.by_index ? "index " + std::to_string(id.index) : "GUID " + id_text;
  auto camera = std::make_unique<IidcCamera>();
  camera->context_ = dc1394_new();
  if (camera->context_ == nullptr) {
    throw HardwareError(device, "IIDC camera " + looking_for +
                                    ": no IIDC camera found (libdc1394 cannot reach an IEEE "
                                    "1394 or USB bus)");
  }
  dc1394camera_list_t* list = nullptr;
  const dc1394error_t error = dc1394_camera_enumerate(camera->context_, &list);
  if (error != DC1394_SUCCESS || list == nullptr) {
    throw HardwareError(device, "IIDC camera " + looking_for +
                                    ": no IIDC camera found (libdc1394 cannot list cameras: " +
                                    Dc1394Error(error) + ")");
  }
  std::vector<uint64_t> guids;
  for (uint32_t i = 0; i < list->num; ++i) guids.push_back(list->ids[i].guid);
  dc1394_camera_free_list(list);
  std::string found;
  for (uint64_t guid : guids) found += (found.empty() ? "" : ", ") + GuidText(guid);
  if (guids.empty()) {
    throw HardwareError(device, "IIDC camera " + looking_for + ": no IIDC camera found");
  }
  uint64_t guid = 0;
  if (id.by_index) {
    if (id.index >= guids.size()) {
      throw HardwareError(device, "IIDC camera " + looking_for + ": no such camera (found " +
                                      std::to_string(guids.size()) + ": " + found + ")");
    }
    guid = guids[id.index];
  } else {
    bool present = false;
    for (uint64_t g : guids) present = present || g == id.guid;
    if (!present) {
      throw HardwareError(device, "IIDC camera " + looking_for +
                                      ": no IIDC camera found with this GUID (found " + found +
                                      ")");
    }
    guid = id.guid;
  }
  const std::string what = "IIDC camera " + GuidText(guid);
  camera->camera_ = dc1394_camera_new(camera->context_, guid);
  if (camera->camera_ == nullptr) throw HardwareError(device, what + ": cannot open it");
  dc1394camera_t* cam = camera->camera_;
  dc1394video_mode_t mode;
  dc1394error_t e = dc1394_video_get_mode(cam, &mode);
  if (e != DC1394_SUCCESS) {
    throw HardwareError(device, what + ": cannot read its video mode: " + Dc1394Error(e));
  }
  e = dc1394_video_set_iso_speed(cam, DC1394_ISO_SPEED_400);
  if (e != DC1394_SUCCESS) {
    throw HardwareError(device, what + ": cannot set the ISO speed: " + Dc1394Error(e));
  }
  if (request.fps > 0.0) SetFrameRate(device, what, cam, mode, request.fps);
  // 4 DMA buffers: enough not to drop frames between grabs, few enough to stay fresh.
  e = dc1394_capture_setup(cam, 4, DC1394_CAPTURE_FLAGS_DEFAULT);
  if (e != DC1394_SUCCESS) {
    throw HardwareError(device, what + ": cannot set up capture: " + Dc1394Error(e));
  }
  camera->capturing_ = true;
  e = dc1394_video_set_transmission(cam, DC1394_ON);
  if (e != DC1394_SUCCESS) {
    throw HardwareError(device, what + ": cannot start transmission: " + Dc1394Error(e));
  }
  camera->transmitting_ = true;
  return std::make_unique<IidcReader>(device, what, std::move(camera));
}

#else

bool HaveIidc() { return false; }

std::unique_ptr<FrameReader> OpenIidc(const std::string& device, const std::string& id_text,
                                      const DeviceRequest& /*request*/) {
  ParseIidcId(device, id_text);
  throw HardwareError(device, "IIDC camera '" + id_text +
                                  "': this build has no libdc1394 (install libdc1394-dev and "
                                  "configure again)");
}

#endif  // SACCADE_HAVE_DC1394

}  // namespace saccade::hw::internal
