#pragma once
// Stereo association and triangulation (seed section 4.2): which face seen by the left eye
// is which face seen by the right, and where it is in the world. Each pair of observations
// (one left, one right) is triangulated from its centres (rays through the calibrated
// cameras, distortion removed, in the world frame from each image's X_WC), and kept when the
// 3D point reprojects into both images within a tolerance (epipolar consistency), lies at a
// plausible depth, and (optionally) has the physical size of a human face. Pairs are then
// chosen greedily by reprojection error, each observation used at most once. With
// refine_disparity, each chosen pair's right centre is then placed where the left
// observation's central patch matches the right image best (normalised cross-correlation,
// sub-pixel peak), so that both rays pass through the same point of the face: box centres of
// one face differ between the eyes by pixels, and at 3 m a pixel of disparity is 5 cm of depth.
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/core/interval.h"

namespace saccade::vision {

/// A face (or any blob) in one image: centre and size, pixels.
struct StereoObservation {
  cv::Point2d center;
  double width_px = 0.0;  ///< horizontal size, for the physical-size check (0: unknown)
  /// From an upright box (a detection or a track window).
  static StereoObservation FromBox(const cv::Rect& box);
};

/// One associated, triangulated pair.
struct StereoMatch {
  int left = -1;                                  ///< index into the left observations
  int right = -1;                                 ///< index into the right observations
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();  ///< triangulated point, world, metres
  double gap_m = 0.0;                             ///< shortest distance between the two rays
  double reprojection_px = 0.0;                   ///< larger of the two reprojection errors
  double depth_m = 0.0;                           ///< along the left optical axis
  double distance_m = 0.0;                        ///< from the midpoint of the two camera centres
  double width_m = 0.0;  ///< physical width from width_px and depth (0: unknown)
};

/// Associates and triangulates left/right observations. Thread-safe (const).
class StereoAssociator {
 public:
  struct Options {
    /// Largest reprojection error of an accepted pair in either image, pixels: kReprojections.
    /// Centres of detections of one face differ between the eyes by a few pixels (box
    /// quantisation).
    double max_reprojection_px = 4.0;
    double min_depth_m = 0.1;   ///< kDepths
    double max_depth_m = 20.0;  ///< kDepths, and > min_depth_m
    /// Physical width of an accepted face, metres, each in kWidths; both 0 disables the check
    /// (else min < max). Human faces (as the cascades box them) are ~0.12 to 0.25 m wide.
    double min_width_m = 0.0;
    double max_width_m = 0.0;
    /// Refine each chosen pair's disparity by matching the left patch in the right image.
    bool refine_disparity = false;

    // The valid values, stated once: IsValid checks them (and the orders across them), and
    // vision.stereo_faces declares its parameters with them (runtime::ParamDecl::Range).
    static constexpr Interval kReprojections = Interval::LeftOpen(0, 1e6);
    static constexpr Interval kDepths = Interval::LeftOpen(0, 1e6);
    static constexpr Interval kWidths = Interval::Closed(0, 1e6);

    bool IsValid(std::string* error) const;
  };

  /// Throws InvalidArgument with IsValid's message.
  StereoAssociator();  ///< default Options
  explicit StereoAssociator(const Options& options);

  /// Associates the observations of `left` and `right` (their metadata give K, distortion
  /// and X_WC). Matches are sorted by distance (closest first). Throws InvalidArgument when
  /// an image's metadata hold no valid camera.
  std::vector<StereoMatch> Associate(const Image& left,
                                     std::span<const StereoObservation> left_observations,
                                     const Image& right,
                                     std::span<const StereoObservation> right_observations) const;

  /// Triangulates one pair without any check (std::nullopt when a ray cannot be formed or
  /// the rays are parallel).
  std::optional<StereoMatch> Triangulate(const Image& left, const StereoObservation& l,
                                         const Image& right, const StereoObservation& r) const;

 private:
  Options options_;
};

/// Index of the match closest to the head (smallest distance_m); std::nullopt when empty.
std::optional<std::size_t> SelectClosest(std::span<const StereoMatch> matches);

}  // namespace saccade::vision
