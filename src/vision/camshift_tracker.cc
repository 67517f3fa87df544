#include "saccade/vision/camshift_tracker.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "internal_cv.h"
#include "saccade/core/error.h"

namespace saccade::vision {

bool CamShiftTracker::Options::IsValid(std::string* error) const {
  std::string what;
  if (!kHueBins.Contains(hue_bins)) {
    what = kHueBins.Refusal("hue_bins", hue_bins);
  } else if (!kSaturationBins.Contains(saturation_bins)) {
    what = kSaturationBins.Refusal("saturation_bins", saturation_bins);
  } else if (!kLevels.Contains(min_saturation)) {
    what = kLevels.Refusal("min_saturation", min_saturation);
  } else if (!kLevels.Contains(min_value)) {
    what = kLevels.Refusal("min_value", min_value);
  } else if (!kSeedFractions.Contains(seed_fraction)) {
    what = kSeedFractions.Refusal("seed_fraction", seed_fraction);
  } else if (!kMassRatios.Contains(min_mass_ratio)) {
    what = kMassRatios.Refusal("min_mass_ratio", min_mass_ratio);
  } else if (!kMinWindows.Contains(min_window_px)) {
    what = kMinWindows.Refusal("min_window_px", min_window_px);
  } else if (!kGrowths.Contains(max_growth)) {
    what = kGrowths.Refusal("max_growth", max_growth);
  } else if (!kIterations.Contains(max_iterations)) {
    what = kIterations.Refusal("max_iterations", max_iterations);
  } else if (!kEpsilons.Contains(epsilon_px)) {
    what = kEpsilons.Refusal("epsilon_px", epsilon_px);
  }
  if (what.empty()) return true;
  if (error) *error = "CamShiftTracker::Options: " + what;
  return false;
}

CamShiftTracker::CamShiftTracker() : CamShiftTracker(Options()) {}

CamShiftTracker::CamShiftTracker(const Options& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument(error);
}

namespace {

// `image` as a cv::Mat of 3 or 4 channels; throws InvalidArgument, naming `who`, on gray8.
cv::Mat Colour(const Image& image, const char* who) {
  cv::Mat whole = internal::WrapMat(image, who);
  if (whole.channels() == 1) {
    throw InvalidArgument(std::string(who) + ": image format gray8, expected rgb8 or rgba8 " +
                          "(CamShift tracks colour)");
  }
  return whole;
}

}  // namespace

cv::Mat CamShiftTracker::BackProject(const Image& image, const char* who,
                                     const std::optional<cv::Rect>& region) const {
  const cv::Mat whole = Colour(image, who);
  const cv::Mat rgb = region ? whole(*region) : whole;
  cv::Mat hsv;
  if (rgb.channels() == 4) {
    cv::Mat rgb3;
    cv::cvtColor(rgb, rgb3, cv::COLOR_RGBA2RGB);
    cv::cvtColor(rgb3, hsv, cv::COLOR_RGB2HSV);
  } else {
    cv::cvtColor(rgb, hsv, cv::COLOR_RGB2HSV);
  }
  if (histogram_.empty()) return hsv;  // Start: the caller builds the histogram
  cv::Mat mask;
  cv::inRange(hsv, cv::Scalar(0, options_.min_saturation, options_.min_value),
              cv::Scalar(180, 256, 256), mask);
  const int channels[] = {0, 1};
  const float hue_range[] = {0.f, 180.f}, sat_range[] = {0.f, 256.f};
  const float* ranges[] = {hue_range, sat_range};
  cv::Mat back;
  cv::calcBackProject(&hsv, 1, channels, histogram_, back, ranges);
  back &= mask;
  return back;
}

bool CamShiftTracker::Start(const Image& image, const cv::Rect& box) {
  histogram_.release();
  state_ = TrackState();
  Colour(image, "CamShiftTracker::Start");
  const cv::Rect image_rect(0, 0, image.width(), image.height());
  if (box.width < options_.min_window_px || box.height < options_.min_window_px ||
      (box & image_rect) != box) {
    state_.reason = "seed box outside the image or smaller than min_window_px";
    return false;
  }
  // Only the box is read: the colour model from the seed at its centre, then the back
  // projection's mass in it. Both are per-pixel operations, so this is the whole image's result
  // to the bit, without converting the whole image twice (5-8 ms at 1024 x 768 on the 2-core
  // development machine, on the steps that start a track).
  const double f = options_.seed_fraction;
  const int w = std::max(1, static_cast<int>(std::lround(box.width * f)));
  const int h = std::max(1, static_cast<int>(std::lround(box.height * f)));
  const cv::Rect seed(box.x + (box.width - w) / 2, box.y + (box.height - h) / 2, w, h);
  const cv::Mat hsv = BackProject(image, "CamShiftTracker::Start", seed);
  cv::Mat mask;
  cv::inRange(hsv, cv::Scalar(0, options_.min_saturation, options_.min_value),
              cv::Scalar(180, 256, 256), mask);
  if (cv::countNonZero(mask) == 0) {
    state_.reason = "seed box holds no saturated, bright pixel: no colour to track";
    return false;
  }
  const int channels[] = {0, 1};
  const int bins[] = {options_.hue_bins, options_.saturation_bins};
  const float hue_range[] = {0.f, 180.f}, sat_range[] = {0.f, 256.f};
  const float* ranges[] = {hue_range, sat_range};
  cv::calcHist(&hsv, 1, channels, mask, histogram_, 2, bins, ranges);
  cv::normalize(histogram_, histogram_, 0, 255, cv::NORM_MINMAX);
  seed_mass_ = cv::sum(BackProject(image, "CamShiftTracker::Start", box))[0];
  seed_area_ = box.area();
  if (seed_mass_ <= 0.0) {
    histogram_.release();
    state_.reason = "seed box has no back-projection mass";
    return false;
  }
  state_.status = TrackState::Status::kTracking;
  state_.window = box;
  state_.box =
      cv::RotatedRect(cv::Point2f(box.x + (box.width - 1) / 2.f, box.y + (box.height - 1) / 2.f),
                      cv::Size2f(box.width, box.height), 0.f);
  state_.mass_ratio = 1.0;
  return true;
}

CamShiftTracker::Shift CamShiftTracker::ShiftIn(const Image& image, const cv::Rect& window,
                                                const cv::Rect& region) const {
  const cv::Mat back = BackProject(image, "CamShiftTracker::Update", region);
  // cv::CamShift moves and resizes `local` in place, within the region.
  cv::Rect local = window - region.tl();
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                  options_.max_iterations, options_.epsilon_px);
  Shift shift;
  shift.box = cv::CamShift(back, local, criteria);
  shift.box.center += cv::Point2f(static_cast<float>(region.x), static_cast<float>(region.y));
  local &= cv::Rect(0, 0, back.cols, back.rows);
  shift.window = local + region.tl();
  shift.mass = local.area() > 0 ? cv::sum(back(local))[0] : 0.0;
  return shift;
}

TrackState CamShiftTracker::Update(const Image& image) {
  if (state_.status != TrackState::Status::kTracking) return state_;
  const cv::Rect image_rect(0, 0, image.width(), image.height());
  cv::Rect window = state_.window & image_rect;
  const auto lose = [&](std::string reason) {
    state_.status = TrackState::Status::kLost;
    state_.reason = std::move(reason);
    return state_;
  };
  if (window.width < options_.min_window_px || window.height < options_.min_window_px) {
    return lose("window left the image");
  }
  // The face moves a few pixels a frame: the colour model back-projected a window's size
  // around the window (a tenth of a 1024 x 768 image for a 90 px face) is what CamShift reads,
  // unless its result reaches that region's edge, where the whole image would have let it go
  // on: then again over the whole image. The same tracks as the whole image's on the demo's
  // scenes, to the bit.
  const cv::Rect around = cv::Rect(window.x - window.width, window.y - window.height,
                                   3 * window.width, 3 * window.height) &
                          image_rect;
  Shift shift = ShiftIn(image, window, around);
  // cv::CamShift sizes the new window from the mean shift's (the old window's size, centred
  // about where the new one is) widened by 10 px, its TOLERANCE: that, with a margin, and the
  // new window widened as much must lie in the region.
  constexpr int kCamShiftMargin = 10;
  const auto widened = [](const cv::Rect& r, int by) {
    return cv::Rect(r.x - by, r.y - by, r.width + 2 * by, r.height + 2 * by);
  };
  const cv::Point centre = (shift.window.tl() + shift.window.br()) / 2;
  const cv::Rect mean_shift(centre.x - window.width / 2, centre.y - window.height / 2, window.width,
                            window.height);
  const cv::Rect read =
      (widened(mean_shift, 2 * kCamShiftMargin + 1) | widened(shift.window, kCamShiftMargin)) &
      image_rect;
  if ((read & around) != read) shift = ShiftIn(image, window, image_rect);
  const cv::RotatedRect box = shift.box;
  state_.box = box;
  state_.window = shift.window;
  state_.mass_ratio = state_.window.area() > 0 ? shift.mass / seed_mass_ : 0.0;
  if (box.size.area() <= 0.f) {
    return lose("no back-projection mass left in the search window");
  }
  if (state_.window.width < options_.min_window_px ||
      state_.window.height < options_.min_window_px) {
    return lose("window collapsed to " + std::to_string(state_.window.width) + " x " +
                std::to_string(state_.window.height) + " px");
  }
  if (state_.window.area() > options_.max_growth * seed_area_) {
    return lose("window grew to " + std::to_string(state_.window.area() / seed_area_) +
                " times the seed's area");
  }
  if (state_.mass_ratio < options_.min_mass_ratio) {
    return lose("back-projection mass fell to " + std::to_string(state_.mass_ratio) +
                " of the seed's");
  }
  return state_;
}

}  // namespace saccade::vision
