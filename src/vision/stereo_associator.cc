#include "saccade/vision/stereo_associator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "internal_cv.h"
#include "saccade/core/error.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/triangulation.h"
#include "saccade/vision/image_camera.h"

namespace saccade::vision {

StereoObservation StereoObservation::FromBox(const cv::Rect& box) {
  return {cv::Point2d(box.x + (box.width - 1) / 2.0, box.y + (box.height - 1) / 2.0),
          static_cast<double>(box.width)};
}

bool StereoAssociator::Options::IsValid(std::string* error) const {
  std::string what;
  if (!kReprojections.Contains(max_reprojection_px)) {
    what = kReprojections.Refusal("max_reprojection_px", max_reprojection_px);
  } else if (!kDepths.Contains(min_depth_m)) {
    what = kDepths.Refusal("min_depth_m", min_depth_m);
  } else if (!kDepths.Contains(max_depth_m)) {
    what = kDepths.Refusal("max_depth_m", max_depth_m);
  } else if (!(max_depth_m > min_depth_m)) {
    what = "max_depth_m " + std::to_string(max_depth_m) + ", expected > min_depth_m (" +
           std::to_string(min_depth_m) + ")";
  } else if (!kWidths.Contains(min_width_m)) {
    what = kWidths.Refusal("min_width_m", min_width_m);
  } else if (!kWidths.Contains(max_width_m)) {
    what = kWidths.Refusal("max_width_m", max_width_m);
  } else if (!(min_width_m == 0.0 && max_width_m == 0.0) && !(max_width_m > min_width_m)) {
    what = "min_width_m " + std::to_string(min_width_m) + ", max_width_m " +
           std::to_string(max_width_m) + ", expected both 0 (off) or min < max";
  }
  if (what.empty()) return true;
  if (error) *error = "StereoAssociator::Options: " + what;
  return false;
}

namespace {

// Where the patch of `gray_l` around `l` (side about 0.6 of the face's width) matches
// `gray_r` best near `r`: the right image point that sees what `l` sees, to a fraction of a
// pixel. std::nullopt when a patch leaves its image or the match is weak (NCC < 0.7).
std::optional<cv::Point2d> MatchInRight(const cv::Mat& gray_l, const cv::Mat& gray_r,
                                        const StereoObservation& l, const StereoObservation& r) {
  const double width = std::max(l.width_px, 12.0);
  const int half = std::max(4, static_cast<int>(std::lround(0.3 * width)));
  const cv::Point cl(static_cast<int>(std::lround(l.center.x)),
                     static_cast<int>(std::lround(l.center.y)));
  const cv::Rect patch(cl.x - half, cl.y - half, 2 * half + 1, 2 * half + 1);
  if ((patch & cv::Rect(0, 0, gray_l.cols, gray_l.rows)) != patch) return std::nullopt;
  // Along the (nearly horizontal) epipolar line a quarter of the width each way; across it a
  // tenth.
  const int sx = std::max(3, static_cast<int>(std::lround(0.25 * width)));
  const int sy = std::max(2, static_cast<int>(std::lround(0.1 * width)));
  const cv::Rect search(static_cast<int>(std::lround(r.center.x)) - half - sx,
                        static_cast<int>(std::lround(r.center.y)) - half - sy, patch.width + 2 * sx,
                        patch.height + 2 * sy);
  if ((search & cv::Rect(0, 0, gray_r.cols, gray_r.rows)) != search) return std::nullopt;
  cv::Mat score;
  cv::matchTemplate(gray_r(search), gray_l(patch), score, cv::TM_CCOEFF_NORMED);
  double best = 0.0;
  cv::Point at;
  cv::minMaxLoc(score, nullptr, &best, nullptr, &at);
  if (!(best >= 0.7) || at.x == 0 || at.y == 0 || at.x == score.cols - 1 ||
      at.y == score.rows - 1) {
    return std::nullopt;  // weak, or the best lies on the search's edge
  }
  // A parabola through the peak and its two neighbours, along each axis.
  const auto vertex = [](float a, float b, float c) {
    const double curvature = static_cast<double>(a) - 2.0 * b + c;
    return curvature < 0.0 ? 0.5 * (a - c) / curvature : 0.0;
  };
  const double dx = vertex(score.at<float>(at.y, at.x - 1), score.at<float>(at.y, at.x),
                           score.at<float>(at.y, at.x + 1));
  const double dy = vertex(score.at<float>(at.y - 1, at.x), score.at<float>(at.y, at.x),
                           score.at<float>(at.y + 1, at.x));
  return cv::Point2d(search.x + at.x + dx + half + (l.center.x - cl.x),
                     search.y + at.y + dy + half + (l.center.y - cl.y));
}

}  // namespace

StereoAssociator::StereoAssociator() : StereoAssociator(Options()) {}

StereoAssociator::StereoAssociator(const Options& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument(error);
}

std::optional<StereoMatch> StereoAssociator::Triangulate(const Image& left,
                                                         const StereoObservation& l,
                                                         const Image& right,
                                                         const StereoObservation& r) const {
  const geometry::CameraModel camera_l = CameraModelOf(left), camera_r = CameraModelOf(right);
  const geometry::Pose X_WL = CameraPoseOf(left), X_WR = CameraPoseOf(right);
  const auto ray_l = camera_l.Unproject({l.center.x, l.center.y});
  const auto ray_r = camera_r.Unproject({r.center.x, r.center.y});
  if (!ray_l || !ray_r) return std::nullopt;
  const geometry::Ray a{X_WL.translation(), (X_WL.linear() * *ray_l).normalized()};
  const geometry::Ray b{X_WR.translation(), (X_WR.linear() * *ray_r).normalized()};
  const geometry::TriangulationResult t = geometry::TriangulateMidpoint(a, b);
  if (t.parallel) return std::nullopt;
  StereoMatch m;
  m.p_W = t.point;
  m.gap_m = t.gap;
  const Eigen::Vector3d p_L = X_WL.inverse() * t.point, p_R = X_WR.inverse() * t.point;
  const auto uv_l = camera_l.Project(p_L), uv_r = camera_r.Project(p_R);
  if (t.behind || !uv_l || !uv_r) {
    m.reprojection_px = std::numeric_limits<double>::infinity();
  } else {
    m.reprojection_px = std::max((*uv_l - Eigen::Vector2d(l.center.x, l.center.y)).norm(),
                                 (*uv_r - Eigen::Vector2d(r.center.x, r.center.y)).norm());
  }
  m.depth_m = p_L.z();
  m.distance_m = (t.point - 0.5 * (X_WL.translation() + X_WR.translation())).norm();
  if (l.width_px > 0.0 && r.width_px > 0.0) {
    // Width of a fronto-parallel object: pixels times depth over focal length, per eye.
    m.width_m = 0.5 * (l.width_px * p_L.z() / camera_l.intrinsics().fx() +
                       r.width_px * p_R.z() / camera_r.intrinsics().fx());
  }
  return m;
}

std::vector<StereoMatch> StereoAssociator::Associate(
    const Image& left, std::span<const StereoObservation> left_observations, const Image& right,
    std::span<const StereoObservation> right_observations) const {
  std::vector<StereoMatch> candidates;
  for (std::size_t i = 0; i < left_observations.size(); ++i) {
    for (std::size_t j = 0; j < right_observations.size(); ++j) {
      std::optional<StereoMatch> m =
          Triangulate(left, left_observations[i], right, right_observations[j]);
      if (!m || !(m->reprojection_px <= options_.max_reprojection_px)) continue;
      if (m->depth_m < options_.min_depth_m || m->depth_m > options_.max_depth_m) continue;
      if (options_.max_width_m > 0.0 && m->width_m > 0.0 &&
          (m->width_m < options_.min_width_m || m->width_m > options_.max_width_m)) {
        continue;
      }
      m->left = static_cast<int>(i);
      m->right = static_cast<int>(j);
      candidates.push_back(*m);
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const StereoMatch& a, const StereoMatch& b) {
    return a.reprojection_px < b.reprojection_px;
  });
  std::vector<bool> used_l(left_observations.size()), used_r(right_observations.size());
  std::vector<StereoMatch> out;
  cv::Mat gray_l, gray_r;
  for (const StereoMatch& m : candidates) {
    if (used_l[m.left] || used_r[m.right]) continue;
    used_l[m.left] = used_r[m.right] = true;
    out.push_back(m);
    if (!options_.refine_disparity) continue;
    if (gray_l.empty()) {
      gray_l = internal::ToGray(left, "StereoAssociator::Associate");
      gray_r = internal::ToGray(right, "StereoAssociator::Associate");
    }
    const StereoObservation& l = left_observations[m.left];
    StereoObservation r = right_observations[m.right];
    const std::optional<cv::Point2d> matched = MatchInRight(gray_l, gray_r, l, r);
    if (!matched) continue;
    r.center = *matched;
    std::optional<StereoMatch> refined = Triangulate(left, l, right, r);
    if (refined && refined->reprojection_px <= options_.max_reprojection_px &&
        refined->depth_m >= options_.min_depth_m && refined->depth_m <= options_.max_depth_m) {
      refined->left = m.left;
      refined->right = m.right;
      refined->width_m = m.width_m;
      out.back() = *refined;
    }
  }
  std::sort(out.begin(), out.end(),
            [](const StereoMatch& a, const StereoMatch& b) { return a.distance_m < b.distance_m; });
  return out;
}

std::optional<std::size_t> SelectClosest(std::span<const StereoMatch> matches) {
  if (matches.empty()) return std::nullopt;
  std::size_t best = 0;
  for (std::size_t i = 1; i < matches.size(); ++i) {
    if (matches[i].distance_m < matches[best].distance_m) best = i;
  }
  return best;
}

}  // namespace saccade::vision
