#pragma once
// Images: an owning Image and a borrowing ImageView, with the metadata every frame carries.
// Row 0 is the top row (OpenCV's convention); rows are tightly packed unless a stride says
// otherwise. Pixel (u, v) has its centre at integer coordinates.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <typeindex>
#include <typeinfo>
#include <utility>
#include <vector>

namespace saccade {

enum class PixelFormat {
  kGray8,    ///< 1 x uint8
  kRgb8,     ///< 3 x uint8, R G B
  kRgba8,    ///< 4 x uint8, R G B A
  kGray16,   ///< 1 x uint16 (depth in mm, 16-bit PNG)
  kFloat32,  ///< 1 x float (depth in metres)
  kUint32,   ///< 1 x uint32 (instance ids)
  // A colour filter array's raw mosaic, one sample a pixel, named as ROS names the encodings
  // (sensor_msgs/image_encodings.hpp): the 2 x 2 cell read row by row from pixel (0, 0), so
  // bayer_rggb8 has R at (0, 0), G at (1, 0) and (0, 1), B at (1, 1) (render/color_filter.h).
  kBayerRggb8,   ///< 1 x uint8, R G / G B
  kBayerBggr8,   ///< 1 x uint8, B G / G R
  kBayerGbrg8,   ///< 1 x uint8, G B / R G
  kBayerGrbg8,   ///< 1 x uint8, G R / B G
  kBayerRggb16,  ///< 1 x uint16, R G / G B
  kBayerBggr16,  ///< 1 x uint16, B G / G R
  kBayerGbrg16,  ///< 1 x uint16, G B / R G
  kBayerGrbg16,  ///< 1 x uint16, G R / B G
};

/// Bytes of one pixel of the format.
int BytesPerPixel(PixelFormat format);
/// "gray8", "rgb8", ..., and the Bayer formats by their ROS encodings ("bayer_rggb8", ...).
const char* ToString(PixelFormat format);
/// Whether the format is a colour filter array's raw mosaic (kBayer*).
bool IsBayer(PixelFormat format);

/// Values of other layers' types that a frame carries, one per type, found by type (no
/// string round trip): geometry's camera model and pose (geometry/image_camera.h). They are
/// immutable and shared: copying the metadata copies pointers.
class TypedValues {
 public:
  template <typename T>
  void Set(std::shared_ptr<const T> value) {
    for (auto& [type, held] : values_) {
      if (type == std::type_index(typeid(T))) {
        held = std::move(value);
        return;
      }
    }
    values_.emplace_back(std::type_index(typeid(T)), std::move(value));
  }
  /// nullptr when the frame carries no T.
  template <typename T>
  const T* Get() const {
    for (const auto& [type, held] : values_) {
      if (type == std::type_index(typeid(T))) return static_cast<const T*>(held.get());
    }
    return nullptr;
  }

 private:
  std::vector<std::pair<std::type_index, std::shared_ptr<const void>>> values_;
};

/// What a frame is and where it came from (DESIGN.md). The camera model (K and the lens
/// distortion of the image as it is) and the camera's pose X_WC (its optical frame in the
/// world) are geometry's types, in `typed` (geometry/image_camera.h).
struct ImageMetadata {
  std::string camera;        ///< camera name ("left", "right", ...)
  double time = 0.0;         ///< simulation (or capture) time, seconds
  int64_t frame_index = 0;   ///< 0, 1, 2, ... per camera
  TypedValues typed;         ///< the camera model and pose
  int exposure_samples = 1;  ///< sub-frames the exposure was drawn in (motion blur)
  /// The controls the frame was taken with (scene/camera_controls.h): exposure time, seconds
  /// (0: an instant), gain, dB, and focus distance, metres (0: none given).
  double exposure_s = 0.0;
  double gain_db = 0.0;
  double focus_m = 0.0;
  bool has_joints = false;  ///< whether the camera rides on a head
  /// The head's joint values at capture (rad, or m for a prismatic joint), named by
  /// `joint_names` in the same order (shared by every image of the head).
  std::vector<double> joints;
  std::shared_ptr<const std::vector<std::string>> joint_names;
};

/// A borrowed, read-only image: pointer, size, format, row stride. Cheap to copy.
class ImageView {
 public:
  ImageView() = default;
  ImageView(const uint8_t* data, int width, int height, PixelFormat format,
            std::size_t stride_bytes = 0, const ImageMetadata* metadata = nullptr);

  const uint8_t* data() const { return data_; }
  int width() const { return width_; }
  int height() const { return height_; }
  PixelFormat format() const { return format_; }
  std::size_t stride() const { return stride_; }
  const uint8_t* row(int y) const { return data_ + static_cast<std::size_t>(y) * stride_; }
  /// nullptr when the view carries none.
  const ImageMetadata* metadata() const { return metadata_; }
  bool empty() const { return data_ == nullptr || width_ == 0 || height_ == 0; }

 private:
  const uint8_t* data_ = nullptr;
  int width_ = 0;
  int height_ = 0;
  PixelFormat format_ = PixelFormat::kRgb8;
  std::size_t stride_ = 0;
  const ImageMetadata* metadata_ = nullptr;
};

/// An owning image with tightly packed rows and its metadata. Moves cheaply; in a process,
/// frames travel as std::shared_ptr<const Image> (never copied, DESIGN.md).
class Image {
 public:
  Image() = default;
  /// Zero-filled. Throws InvalidArgument when width or height is negative.
  Image(int width, int height, PixelFormat format);
  /// A copy of `height` rows of `pixels`, each `stride` bytes apart (at least a packed row),
  /// without the zero-fill first: for frames that arrive in another's memory (a DDS sample, a
  /// device's buffer). Throws InvalidArgument as above, or when `stride` is shorter than a row.
  Image(int width, int height, PixelFormat format, const uint8_t* pixels, std::size_t stride);

  int width() const { return width_; }
  int height() const { return height_; }
  PixelFormat format() const { return format_; }
  std::size_t stride() const { return static_cast<std::size_t>(width_) * BytesPerPixel(format_); }
  uint8_t* data() { return pixels_.data(); }
  const uint8_t* data() const { return pixels_.data(); }
  std::size_t size_bytes() const { return pixels_.size(); }
  uint8_t* row(int y) { return pixels_.data() + static_cast<std::size_t>(y) * stride(); }
  const uint8_t* row(int y) const {
    return pixels_.data() + static_cast<std::size_t>(y) * stride();
  }
  ImageMetadata& metadata() { return metadata_; }
  const ImageMetadata& metadata() const { return metadata_; }
  ImageView view() const { return {data(), width_, height_, format_, stride(), &metadata_}; }
  bool empty() const { return pixels_.empty(); }

 private:
  int width_ = 0;
  int height_ = 0;
  PixelFormat format_ = PixelFormat::kRgb8;
  std::vector<uint8_t> pixels_;
  ImageMetadata metadata_;
};

}  // namespace saccade
