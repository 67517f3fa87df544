#pragma once
// CamShift tracking (seed: the detector alone loses faces under perspective change, so a
// detection seeds a colour tracker): a hue-saturation histogram of the detected face,
// back-projected into each new frame, and cv::CamShift's mean shift with an adaptive,
// rotated window. The track is declared lost when the window collapses, blows up, or the
// back-projection mass inside it falls below a fraction of the mass at the seed; the caller
// then re-detects (e.g. FaceDetector near window()) and calls Start again.
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "saccade/core/image.h"
#include "saccade/core/interval.h"

namespace saccade::vision {

/// What one Update found.
struct TrackState {
  enum class Status { kTracking, kLost, kNotStarted };
  Status status = Status::kNotStarted;
  cv::RotatedRect box;      ///< CamShift's rotated box (pixels; angle in degrees)
  cv::Rect window;          ///< the upright search window for the next frame
  double mass_ratio = 0.0;  ///< back-projection mass in the window / mass at Start
  std::string reason;       ///< why the track was lost ("" while tracking)
  bool lost() const { return status != Status::kTracking; }
  cv::Point2d Center() const { return {box.center.x, box.center.y}; }
};

/// One CamShift track. Not thread-safe (it is state); one per tracked object.
class CamShiftTracker {
 public:
  struct Options {
    int hue_bins = 30;         ///< histogram bins over OpenCV's hue 0 .. 180: kHueBins
    int saturation_bins = 32;  ///< bins over saturation 0 .. 256: kSaturationBins
    int min_saturation = 30;   ///< pixels less saturated are ignored (grey has no hue): kLevels
    int min_value = 30;        ///< darker pixels are ignored (noisy hue): kLevels
    /// Fraction (per side) of the seed box, about its centre, whose colours make the model:
    /// the detector's box holds some background at its corners. kSeedFractions.
    double seed_fraction = 0.7;
    /// Lost when the back-projection mass in the window falls below this fraction of the
    /// seed's: kMassRatios.
    double min_mass_ratio = 0.3;
    /// Lost when the window's side falls below this (pixels, kMinWindows) ...
    int min_window_px = 8;
    /// ... or its area grows beyond this multiple of the seed box's (kGrowths): it spread
    /// into a background of similar colour.
    double max_growth = 6.0;
    int max_iterations = 10;  ///< mean-shift iterations per frame: kIterations
    double epsilon_px = 0.5;  ///< mean-shift convergence, pixels: kEpsilons

    // The valid values, stated once: IsValid checks them, and vision.camshift declares its
    // parameters with them (runtime::ParamDecl::Range(const Interval&)).
    static constexpr Interval kHueBins = Interval::Closed(2, 180);
    static constexpr Interval kSaturationBins = Interval::Closed(1, 256);
    static constexpr Interval kLevels = Interval::Closed(0, 255);
    static constexpr Interval kSeedFractions = Interval::LeftOpen(0, 1);
    static constexpr Interval kMassRatios = Interval::RightOpen(0, 1);
    static constexpr Interval kMinWindows = Interval::AtLeast(1);
    static constexpr Interval kGrowths = Interval::Above(1);
    static constexpr Interval kIterations = Interval::AtLeast(1);
    static constexpr Interval kEpsilons = Interval::Above(0);

    bool IsValid(std::string* error) const;
  };

  /// Throws InvalidArgument with IsValid's message.
  CamShiftTracker();  ///< default Options
  explicit CamShiftTracker(const Options& options);

  /// Learns the colour model inside `box` of an rgb8 or rgba8 `image` and starts tracking
  /// there. Returns false (and is not tracking) when the box is not inside the image or holds
  /// no usable colour (all grey or dark). Does not throw on the box; throws InvalidArgument on
  /// another image format.
  bool Start(const Image& image, const cv::Rect& box);

  /// Moves the track to `image` (same camera, next frame). After loss, returns kLost until
  /// Start is called again; before any Start, kNotStarted. The colour model is back-projected
  /// around the window only (a window's size each side); a result that reaches that region's
  /// edge inside the image is computed again over the whole image.
  TrackState Update(const Image& image);

  bool tracking() const { return state_.status == TrackState::Status::kTracking; }
  /// The latest state (after Start: the seed box itself).
  const TrackState& state() const { return state_; }
  const Options& options() const { return options_; }

 private:
  // The back projection of `region` of `image` (the whole image by default); before the colour
  // model is learnt (Start), that region in HSV.
  cv::Mat BackProject(const Image& image, const char* who,
                      const std::optional<cv::Rect>& region = std::nullopt) const;
  // CamShift from `window` over `region` of `image`: the state's box and window in the image's
  // pixels, and the back projection's mass in the new window.
  struct Shift {
    cv::RotatedRect box;
    cv::Rect window;
    double mass = 0.0;
  };
  Shift ShiftIn(const Image& image, const cv::Rect& window, const cv::Rect& region) const;

  Options options_;
  cv::Mat histogram_;  // hue x saturation, normalised to 0 .. 255
  double seed_mass_ = 0.0;
  double seed_area_ = 0.0;
  TrackState state_;
};

}  // namespace saccade::vision
