#pragma once
// Dense stereo depth from the two eyes at any vergence (issue 44, item 1).
//
// Each pair is rectified from its own geometry: the cameras' calibrations and their poses X_WC
// (from the head's kinematics), so that a verging head gives a new rectification at every
// posture. Both views are resampled (distortion removed, turned by Bouguet's rotations,
// geometry/stereo_rectification.h) into one pinhole camera K_rect of focal f = scale * fx_left,
// centred, the same for both eyes: corresponding points then lie on one row and the disparity of
// a point at depth z is d = f B / z > 0 (B the baseline), zero at infinity. OpenCV's
// semi-global matcher (cv::StereoSGBM, Hirschmueller 2008) computes the disparity of the left
// rectified view; an optional left-right check (the right view's disparity, matched on the
// mirrored pair) discards occlusions and mismatches and gives each pixel its confidence.
//
// The depth image lies in the rectified left camera R: the left camera's optical centre, turned
// by R1 and with the pinhole K_rect. Its pose X_WR = X_WL * R1^T is part of the result, so that
// its points go to the world exactly (WorldPoints).
//
// Scoring (Middlebury's measures, Scharstein and Szeliski 2002): the renderer's ground-truth
// depth of the left camera, resampled into the rectified view (TruthDisparity), gives the true
// disparity of every pixel; ScoreDisparity counts the bad pixels at 1 and 2 px and the RMS depth
// error by range.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/core/interval.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/intrinsics.h"
#include "saccade/geometry/pose.h"

namespace saccade::vision {

/// One eye's view: its image (rgb8, rgba8 or gray8 of the camera's size), calibration and
/// pose in the world (X_WC, OpenCV optical frame).
struct StereoView {
  const Image* image = nullptr;
  geometry::CameraModel camera{geometry::Intrinsics(640, 480, 500.0, 500.0, 319.5, 239.5)};
  geometry::Pose X_WC = geometry::Pose::Identity();
};

/// A rectified pair's depth. Images are of the rectified size (rectified.width() x height()).
struct StereoDepth {
  /// kFloat32, metres: z of the surface point in the rectified left camera R; 0: no match.
  Image depth;
  /// kFloat32 in [0, 1]: 0 where depth is 0; with the left-right check, 1 - |d_L - d_R| / (2
  /// lr_max_diff_px) (so at least 0.5 where kept); without it, 1 wherever matched.
  Image confidence;
  /// kFloat32, pixels: the left rectified view's disparity; -1 where unmatched.
  Image disparity;
  /// The rectified left view: K_rect, no distortion.
  geometry::Intrinsics rectified{640, 480, 500.0, 500.0, 319.5, 239.5};
  geometry::Pose X_WR = geometry::Pose::Identity();  ///< the rectified left camera in the world
  Eigen::Matrix3d R1 = Eigen::Matrix3d::Identity();  ///< left optical frame -> rectified frame
  Eigen::Matrix3d R2 = Eigen::Matrix3d::Identity();  ///< right optical frame -> its rectified frame
  /// The left camera lies at +x of the right one in the rectified frame (the views were
  /// matched mirrored): a left pixel x matches right pixel x + d instead of x - d.
  bool mirrored = false;
  double baseline_m = 0.0;  ///< B: distance between optical centres
  double focal_px = 0.0;    ///< f of K_rect: d = f B / z
};

/// Disparity and depth measured against the truth (Middlebury's measures).
struct StereoScore {
  int64_t truth_pixels = 0;    ///< pixels with a true disparity (a surface, in both views' range)
  int64_t matched_pixels = 0;  ///< of those, pixels the matcher gave a disparity
  double density = 0.0;        ///< matched / truth
  double bad_1px = 0.0;        ///< share of matched pixels whose |d - d_true| > 1 px
  double bad_2px = 0.0;        ///< > 2 px
  double disparity_rms_px = 0.0;
  /// RMS depth error (m) of the matched pixels that are not bad at 2 px (gross mismatches are
  /// bad_2px's, and one of them at 1 px of disparity would be metres of depth) whose true depth
  /// lies in [range_edges[i], range_edges[i + 1]); NaN where no pixel falls in the bin.
  std::vector<double> range_edges_m;
  std::vector<double> depth_rms_m;
  std::vector<int64_t> range_pixels;
};

/// Semi-global matching of a rectified pair. Thread-safe after construction (Compute is const).
class DenseStereo {
 public:
  struct Options {
    /// Size of the rectified views against the left camera's: [0, 1]; 0 (the default): the
    /// smallest size at which f B (the rectified focal length times the baseline) is at least
    /// kAutoFocalBaseline, at least a quarter and at most full size. On POPEYE (1290 px, 0.2 m)
    /// that is half size: 1 px of disparity is 0.8 cm of depth at 1 m and 5 cm at 2.5 m before
    /// SGBM's 1/16 px interpolation, for a quarter of full size's cost; a head with a short
    /// baseline (the humanoid's 6.8 cm) matches at full size.
    double scale = 0.0;
    static constexpr double kAutoFocalBaseline = 129.0;  ///< px m: POPEYE at half size
    /// The nearest depth matched (m): sets the disparity range, f B / min_depth_m (rounded up to
    /// 16). Nearer surfaces are unmatched, not wrong.
    double min_depth_m = 0.6;
    int block_size = 5;        ///< SGBM's matched block, odd, 1..11 px
    int uniqueness_ratio = 5;  ///< %: the best cost must beat the second best by this much
    int speckle_window =
        100;  ///< blobs of fewer pixels with other disparities are dropped (0: off)
    bool left_right_check = true;  ///< match the mirrored pair too and keep consistent pixels
    double lr_max_diff_px = 1.0;   ///< the largest |d_L - d_R| kept

    static constexpr Interval kScales = Interval::Closed(0.0, 1.0);
    static constexpr Interval kMinDepths = Interval::Above(0.0);
    static constexpr Interval kBlockSizes = Interval::Closed(1, 11);
    static constexpr Interval kUniquenessRatios = Interval::Closed(0, 100);
    static constexpr Interval kSpeckleWindows = Interval::Closed(0, 10000);
    static constexpr Interval kLrDiffs = Interval::Above(0.0);

    bool IsValid(std::string* error) const;
  };

  DenseStereo();  ///< default Options
  /// Throws InvalidArgument with IsValid's message.
  explicit DenseStereo(const Options& options);

  /// The depth of the left view. Throws InvalidArgument when an image is missing, of another
  /// size than its camera's or of a format other than rgb8, rgba8 or gray8, when the
  /// optical centres coincide, or when the pair lies one above the other (a vertical baseline
  /// is not matched).
  StereoDepth Compute(const StereoView& left, const StereoView& right) const;

  const Options& options() const { return options_; }

 private:
  Options options_;
};

/// The true disparity of the rectified left view (kFloat32, px; -1 where there is no surface,
/// or where the matching pixel of the right view lies off the right camera's image) from the
/// renderer's depth of the left camera (kFloat32 z in the left optical frame, 0 for none; of
/// `left`'s size): each rectified pixel samples the depth where its ray meets the left image
/// (nearest pixel, so that no value is blended across an edge). Occlusions by nearer surfaces
/// are not removed: they count as unmatched or bad, as in Middlebury's "all" measures. Throws
/// InvalidArgument when the depth is not kFloat32 of the left camera's size.
Image TruthDisparity(const Image& left_depth, const geometry::CameraModel& left,
                     const geometry::CameraModel& right, const StereoDepth& stereo);

/// Middlebury's measures of `stereo` against the true disparity, with the depth error binned by
/// `range_edges_m` (ascending). Pixels within `border_px` of the image's edge are left out.
StereoScore ScoreDisparity(const StereoDepth& stereo, const Image& truth_disparity,
                           const std::vector<double>& range_edges_m = {1.0, 2.0, 3.0},
                           int border_px = 0);

/// The world points (m) of every `stride`-th row and column of the depth whose confidence is at
/// least `min_confidence`, in row order.
std::vector<Eigen::Vector3d> WorldPoints(const StereoDepth& stereo, int stride = 1,
                                         double min_confidence = 0.0);

}  // namespace saccade::vision
