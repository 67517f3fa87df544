#include "saccade/hw/stereo_source.h"

#include <cmath>
#include <string>
#include <utility>

#include "saccade/core/error.h"

namespace saccade::hw {
namespace {

void CheckSkew(double max_skew_s) {
  if (!std::isfinite(max_skew_s) || max_skew_s < 0.0) {
    throw InvalidArgument("StereoSource: max_skew_s must be a finite time >= 0 s, got " +
                          std::to_string(max_skew_s));
  }
}

}  // namespace

StereoSource::StereoSource(std::unique_ptr<CameraSource> left, std::unique_ptr<CameraSource> right,
                           double max_skew_s)
    : left_(std::move(left)), right_(std::move(right)), max_skew_s_(max_skew_s) {
  if (left_ == nullptr || right_ == nullptr) {
    throw InvalidArgument(std::string("StereoSource: the ") +
                          (left_ == nullptr ? "left" : "right") +
                          " source is null, expected an opened CameraSource");
  }
  CheckSkew(max_skew_s);
  right_->set_epoch(left_->epoch());
}

std::optional<StereoFrame> StereoSource::Grab() {
  while (!ended_) {
    if (held_left_ == nullptr && held_right_ == nullptr && left_->live() && right_->live()) {
      // Both exposures first, then the (slower) decoding.
      const bool left_latched = left_->Latch();
      const bool right_latched = right_->Latch();
      if (left_latched) held_left_ = left_->Retrieve();
      if (right_latched) held_right_ = right_->Retrieve();
    } else {
      if (held_left_ == nullptr) held_left_ = left_->Grab();
      if (held_right_ == nullptr && held_left_ != nullptr) held_right_ = right_->Grab();
    }
    if (held_left_ == nullptr || held_right_ == nullptr) {
      ended_ = true;
      held_left_.reset();
      held_right_.reset();
      break;
    }
    const double left_time = held_left_->metadata().time;
    const double right_time = held_right_->metadata().time;
    if (std::abs(right_time - left_time) <= max_skew_s_) {
      StereoFrame pair{std::move(held_left_), std::move(held_right_)};
      held_left_.reset();
      held_right_.reset();
      ++pairs_;
      return pair;
    }
    if (left_time < right_time) {
      held_left_.reset();
      ++dropped_left_;
    } else {
      held_right_.reset();
      ++dropped_right_;
    }
  }
  return std::nullopt;
}

std::unique_ptr<StereoSource> OpenStereoSource(const CameraSourceSpec& left,
                                               const CameraSourceSpec& right, double max_skew_s) {
  CheckSkew(max_skew_s);  // before opening any device
  auto left_source = OpenCameraSource(left);
  auto right_source = OpenCameraSource(right);
  return std::make_unique<StereoSource>(std::move(left_source), std::move(right_source),
                                        max_skew_s);
}

}  // namespace saccade::hw
