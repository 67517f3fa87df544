#pragma once
// Two camera sources paired into stereo frames by their time stamps.
//
// Pairing rule: the pairer holds at most one frame of each camera. When both are held and
// their time stamps differ by at most max_skew_s, they are a pair. Otherwise the older frame
// is dropped (counted in dropped_left() or dropped_right()) and the next frame of that camera
// is taken, since a later frame of the other camera would only be further from it. The first
// acceptable pair is taken, not the closest one; frames must come in time order. When both
// cameras are live devices and no frame is held, both are latched (CameraSource::Latch) before
// either is decoded, so that the two exposures are taken as close together as the drivers
// allow.

#include <cstdint>
#include <memory>
#include <optional>

#include "saccade/core/image.h"
#include "saccade/hw/camera_source.h"

namespace saccade::hw {

/// A left and a right frame taken within the skew of each other.
struct StereoFrame {
  std::shared_ptr<Image> left;
  std::shared_ptr<Image> right;
  /// right's time minus left's, seconds.
  double skew_s() const { return right->metadata().time - left->metadata().time; }
};

/// Pairs the frames of two sources. Not thread-safe: one thread grabs.
class StereoSource {
 public:
  /// Takes both sources; the right one gets the left one's epoch, so that live time stamps
  /// count from the same instant. Throws InvalidArgument when a source is null or max_skew_s
  /// is negative or not finite.
  StereoSource(std::unique_ptr<CameraSource> left, std::unique_ptr<CameraSource> right,
               double max_skew_s);

  /// The next pair (see the rule above); std::nullopt when either source has ended, and on
  /// every call after that. Throws what the sources throw (HardwareError).
  std::optional<StereoFrame> Grab();

  CameraSource& left() { return *left_; }
  CameraSource& right() { return *right_; }
  const CameraSource& left() const { return *left_; }
  const CameraSource& right() const { return *right_; }
  double max_skew_s() const { return max_skew_s_; }
  /// Frames dropped because the other camera had no frame within the skew.
  int64_t dropped_left() const { return dropped_left_; }
  int64_t dropped_right() const { return dropped_right_; }
  /// Pairs delivered.
  int64_t pairs() const { return pairs_; }

 private:
  std::unique_ptr<CameraSource> left_;
  std::unique_ptr<CameraSource> right_;
  double max_skew_s_;
  std::shared_ptr<Image> held_left_;
  std::shared_ptr<Image> held_right_;
  bool ended_ = false;
  int64_t dropped_left_ = 0;
  int64_t dropped_right_ = 0;
  int64_t pairs_ = 0;
};

/// Opens both cameras (OpenCameraSource) and pairs them. Throws as OpenCameraSource and the
/// StereoSource constructor.
std::unique_ptr<StereoSource> OpenStereoSource(const CameraSourceSpec& left,
                                               const CameraSourceSpec& right, double max_skew_s);

}  // namespace saccade::hw
