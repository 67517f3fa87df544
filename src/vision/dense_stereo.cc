#include "saccade/vision/dense_stereo.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "saccade/core/error.h"
#include "saccade/geometry/stereo_rectification.h"
#include "vision/internal_cv.h"

namespace saccade::vision {
namespace dense_stereo_internal {

cv::Matx33d ToCv(const Eigen::Matrix3d& m) {
  cv::Matx33d out;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out(r, c) = m(r, c);
  }
  return out;
}

// The maps that resample `camera`'s image into the rectified view (rotation R, pinhole K_rect).
void RectifyMaps(const geometry::CameraModel& camera, const Eigen::Matrix3d& R,
                 const geometry::Intrinsics& rect, cv::Mat* map_x, cv::Mat* map_y) {
  const auto& in = camera.intrinsics();
  const cv::Matx33d K(in.fx(), in.skew(), in.cx(), 0.0, in.fy(), in.cy(), 0.0, 0.0, 1.0);
  const cv::Matx33d K_rect = ToCv(rect.Matrix());
  const cv::Size size(rect.width(), rect.height());
  const std::vector<double>& c = camera.distortion().coefficients();
  switch (camera.distortion().model()) {
    case geometry::DistortionModel::kFisheye:
      cv::fisheye::initUndistortRectifyMap(K, c, ToCv(R), K_rect, size, CV_32FC1, *map_x, *map_y);
      break;
    case geometry::DistortionModel::kRadialTangential:
      cv::initUndistortRectifyMap(K, c, ToCv(R), K_rect, size, CV_32FC1, *map_x, *map_y);
      break;
    case geometry::DistortionModel::kNone:
      cv::initUndistortRectifyMap(K, cv::noArray(), ToCv(R), K_rect, size, CV_32FC1, *map_x,
                                  *map_y);
      break;
  }
}

void CheckView(const StereoView& view, const char* which) {
  if (view.image == nullptr) {
    throw InvalidArgument(std::string("DenseStereo::Compute: the ") + which + " image is missing");
  }
  const auto& in = view.camera.intrinsics();
  if (view.image->width() != in.width() || view.image->height() != in.height()) {
    throw InvalidArgument(std::string("DenseStereo::Compute: the ") + which + " image is " +
                          std::to_string(view.image->width()) + " x " +
                          std::to_string(view.image->height()) + ", its camera's size is " +
                          std::to_string(in.width()) + " x " + std::to_string(in.height()));
  }
}

Image FloatImage(const cv::Mat& mat) {
  Image out(mat.cols, mat.rows, PixelFormat::kFloat32);
  cv::Mat dst(out.height(), out.width(), CV_32FC1, out.data(), out.stride());
  mat.copyTo(dst);
  return out;
}

cv::Mat WrapFloat(const Image& image) {
  return cv::Mat(image.height(), image.width(), CV_32FC1, const_cast<uint8_t*>(image.data()),
                 image.stride());
}

// SGBM's fixed-point disparity (16 x px) as float px, -1 where unmatched.
cv::Mat ToPixels(const cv::Mat& fixed) {
  cv::Mat out(fixed.size(), CV_32FC1);
  for (int y = 0; y < fixed.rows; ++y) {
    const int16_t* s = fixed.ptr<int16_t>(y);
    float* d = out.ptr<float>(y);
    for (int x = 0; x < fixed.cols; ++x) d[x] = s[x] > 0 ? s[x] / 16.0f : -1.0f;
  }
  return out;
}

// The left view's disparity (px, -1 unmatched). SGBM leaves the first num_disparities columns
// unmatched (their search range leaves the right image), so both views are padded on the left
// by that many black columns and the result cropped: every pixel is searched over the
// disparities that stay inside the right view.
cv::Mat Match(cv::StereoSGBM& sgbm, int num_disparities, const cv::Mat& left,
              const cv::Mat& right) {
  cv::Mat padded_l, padded_r, fixed;
  cv::copyMakeBorder(left, padded_l, 0, 0, num_disparities, 0, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::copyMakeBorder(right, padded_r, 0, 0, num_disparities, 0, cv::BORDER_CONSTANT, cv::Scalar(0));
  sgbm.compute(padded_l, padded_r, fixed);
  return ToPixels(fixed.colRange(num_disparities, fixed.cols));
}

// Whether rectified pixel (x, y) samples `image` at least `margin` pixels inside its edges.
bool Inside(const cv::Mat& map_x, const cv::Mat& map_y, int x, int y, const Image& image,
            double margin) {
  if (x < 0 || x >= map_x.cols) return false;
  const float sx = map_x.at<float>(y, x), sy = map_y.at<float>(y, x);
  return sx >= margin && sy >= margin && sx <= image.width() - 1 - margin &&
         sy <= image.height() - 1 - margin;
}

}  // namespace dense_stereo_internal

using dense_stereo_internal::FloatImage;
using dense_stereo_internal::Inside;
using dense_stereo_internal::WrapFloat;

bool DenseStereo::Options::IsValid(std::string* error) const {
  std::string what;
  if (!kScales.Contains(scale)) {
    what = kScales.Refusal("scale", scale);
  } else if (!kMinDepths.Contains(min_depth_m)) {
    what = kMinDepths.Refusal("min_depth_m", min_depth_m);
  } else if (!kBlockSizes.Contains(block_size) || block_size % 2 == 0) {
    what = "block_size: " + std::to_string(block_size) + ", expected an odd number in 1..11";
  } else if (!kUniquenessRatios.Contains(uniqueness_ratio)) {
    what = kUniquenessRatios.Refusal("uniqueness_ratio", uniqueness_ratio);
  } else if (!kSpeckleWindows.Contains(speckle_window)) {
    what = kSpeckleWindows.Refusal("speckle_window", speckle_window);
  } else if (!kLrDiffs.Contains(lr_max_diff_px)) {
    what = kLrDiffs.Refusal("lr_max_diff_px", lr_max_diff_px);
  }
  if (what.empty()) return true;
  if (error) *error = "DenseStereo::Options: " + what;
  return false;
}

DenseStereo::DenseStereo() : DenseStereo(Options()) {}

DenseStereo::DenseStereo(const Options& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument(error);
}

namespace dense_stereo_internal {

// The rectified pair's geometry: K_rect, R1, R2, X_WR, the baseline, whether mirrored. Throws
// for coinciding centres and a vertical pair.
StereoDepth Rectification(const StereoView& left, const StereoView& right, double scale) {
  // scale 0: chosen from the baseline (Options::scale).
  // p_R = R p_L + T (cv::stereoCalibrate's convention).
  const geometry::Pose X_RL = right.X_WC.inverse() * left.X_WC;
  const Eigen::Vector3d T = X_RL.translation();
  if (!(T.norm() > 1e-9)) {
    throw InvalidArgument("DenseStereo::Compute: the two cameras' optical centres coincide");
  }
  const geometry::StereoRectification rect = geometry::RectifyStereo(X_RL.linear(), T);
  if (rect.vertical) {
    throw InvalidArgument(
        "DenseStereo::Compute: the cameras lie one above the other (a vertical baseline); "
        "only side-by-side pairs are matched");
  }
  StereoDepth out;
  out.baseline_m = std::abs(rect.T_rect.x());
  const auto& in = left.camera.intrinsics();
  if (scale == 0.0) {
    scale = std::clamp(DenseStereo::Options::kAutoFocalBaseline / (in.fx() * out.baseline_m), 0.25,
                       1.0);
  }
  const int width = std::max(16, static_cast<int>(std::lround(in.width() * scale)));
  const int height = std::max(8, static_cast<int>(std::lround(in.height() * scale)));
  out.focal_px = in.fx() * width / static_cast<double>(in.width());
  out.rectified = geometry::Intrinsics(width, height, out.focal_px, out.focal_px, (width - 1) / 2.0,
                                       (height - 1) / 2.0);
  out.R1 = rect.R1;
  out.R2 = rect.R2;
  out.X_WR = left.X_WC * geometry::MakePose(rect.R1.transpose(), Eigen::Vector3d::Zero());
  // The left camera must be on the left (T_rect.x < 0: its centre at -x seen from the right).
  out.mirrored = rect.T_rect.x() > 0;
  return out;
}

// Keeps the left disparities that the right view's (matched on the mirrored pair) confirms
// within `limit` px, and gives them their confidence.
void LeftRightCheck(cv::StereoSGBM& sgbm, int num_disparities, const cv::Mat& gray_l,
                    const cv::Mat& gray_r, double limit, cv::Mat* disparity, cv::Mat* confidence) {
  cv::Mat mirrored_l, mirrored_r;
  cv::flip(gray_l, mirrored_l, 1);
  cv::flip(gray_r, mirrored_r, 1);
  cv::Mat disparity_r = Match(sgbm, num_disparities, mirrored_r, mirrored_l);
  cv::flip(disparity_r, disparity_r, 1);
  for (int y = 0; y < disparity->rows; ++y) {
    float* d = disparity->ptr<float>(y);
    const float* dr = disparity_r.ptr<float>(y);
    float* c = confidence->ptr<float>(y);
    for (int x = 0; x < disparity->cols; ++x) {
      if (d[x] <= 0) continue;
      const int xr = static_cast<int>(std::lround(x - d[x]));
      const double diff = xr >= 0 ? std::abs(d[x] - dr[xr]) : limit + 1.0;
      if (xr < 0 || dr[xr] <= 0 || diff > limit) {
        d[x] = -1.0f;
      } else {
        c[x] = static_cast<float>(1.0 - diff / (2.0 * limit));
      }
    }
  }
}

// Where a rectified view samples outside its camera's image (a verged or distorted pair turns
// parts of each view off the sensor) it is black, and black matches black: only pixels whose
// own and matched sources lie inside both images (by `margin` px) are kept.
void DropOffSensor(const cv::Mat (&maps)[4], const StereoView& left, const StereoView& right,
                   bool mirrored, double margin, cv::Mat* disparity, cv::Mat* confidence) {
  const int sign = mirrored ? 1 : -1;  // the right view's column of left column x: x + sign d
  for (int y = 0; y < disparity->rows; ++y) {
    float* d = disparity->ptr<float>(y);
    float* c = confidence->ptr<float>(y);
    for (int x = 0; x < disparity->cols; ++x) {
      if (d[x] <= 0) continue;
      const int xr = static_cast<int>(std::lround(x + sign * d[x]));
      if (!Inside(maps[0], maps[1], x, y, *left.image, margin) ||
          !Inside(maps[2], maps[3], xr, y, *right.image, margin)) {
        d[x] = -1.0f;
        c[x] = 0.0f;
      }
    }
  }
}

cv::Mat DepthOf(const cv::Mat& disparity, double fb) {
  cv::Mat depth(disparity.size(), CV_32FC1, cv::Scalar(0.0f));
  for (int y = 0; y < disparity.rows; ++y) {
    const float* d = disparity.ptr<float>(y);
    float* z = depth.ptr<float>(y);
    for (int x = 0; x < disparity.cols; ++x) {
      if (d[x] > 0) z[x] = static_cast<float>(fb / d[x]);
    }
  }
  return depth;
}

}  // namespace dense_stereo_internal

StereoDepth DenseStereo::Compute(const StereoView& left, const StereoView& right) const {
  using namespace dense_stereo_internal;
  CheckView(left, "left");
  CheckView(right, "right");
  StereoDepth out = Rectification(left, right, options_.scale);
  cv::Mat maps[4];
  RectifyMaps(left.camera, out.R1, out.rectified, &maps[0], &maps[1]);
  RectifyMaps(right.camera, out.R2, out.rectified, &maps[2], &maps[3]);
  cv::Mat gray_l, gray_r;
  cv::remap(internal::ToGray(*left.image, "DenseStereo::Compute"), gray_l, maps[0], maps[1],
            cv::INTER_LINEAR);
  cv::remap(internal::ToGray(*right.image, "DenseStereo::Compute"), gray_r, maps[2], maps[3],
            cv::INTER_LINEAR);
  if (out.mirrored) {  // mirror both: the left camera is then on the left
    cv::flip(gray_l, gray_l, 1);
    cv::flip(gray_r, gray_r, 1);
  }
  const int width = out.rectified.width();
  const int max_disparity = static_cast<int>(
      std::ceil(out.focal_px * out.baseline_m / options_.min_depth_m / 16.0) * 16.0);
  const int num_disparities = std::clamp(max_disparity, 16, std::max(16, width / 16 * 16));
  const int bs = options_.block_size;
  const cv::Ptr<cv::StereoSGBM> sgbm = cv::StereoSGBM::create(
      0, num_disparities, bs, 8 * bs * bs, 32 * bs * bs, -1, 63, options_.uniqueness_ratio,
      options_.speckle_window, 2, cv::StereoSGBM::MODE_SGBM_3WAY);
  cv::Mat disparity = Match(*sgbm, num_disparities, gray_l, gray_r);
  cv::Mat confidence(disparity.size(), CV_32FC1, cv::Scalar(0.0f));
  if (options_.left_right_check) {
    LeftRightCheck(*sgbm, num_disparities, gray_l, gray_r, options_.lr_max_diff_px, &disparity,
                   &confidence);
  } else {
    confidence.setTo(1.0f, disparity > 0);
  }
  if (out.mirrored) {
    cv::flip(disparity, disparity, 1);
    cv::flip(confidence, confidence, 1);
  }
  DropOffSensor(maps, left, right, out.mirrored, options_.block_size / 2 + 1, &disparity,
                &confidence);
  out.depth = FloatImage(DepthOf(disparity, out.focal_px * out.baseline_m));
  out.confidence = FloatImage(confidence);
  out.disparity = FloatImage(disparity);
  for (Image* image : {&out.depth, &out.confidence, &out.disparity}) {
    image->metadata() = left.image->metadata();
  }
  return out;
}

Image TruthDisparity(const Image& left_depth, const geometry::CameraModel& left,
                     const geometry::CameraModel& right, const StereoDepth& stereo) {
  const auto& in = left.intrinsics();
  if (left_depth.format() != PixelFormat::kFloat32 || left_depth.width() != in.width() ||
      left_depth.height() != in.height()) {
    throw InvalidArgument("TruthDisparity: the depth must be float32 of the left camera's size " +
                          std::to_string(in.width()) + " x " + std::to_string(in.height()));
  }
  cv::Mat map_x, map_y;
  dense_stereo_internal::RectifyMaps(left, stereo.R1, stereo.rectified, &map_x, &map_y);
  cv::Mat z_left, right_x, right_y;
  cv::remap(WrapFloat(left_depth), z_left, map_x, map_y, cv::INTER_NEAREST, cv::BORDER_CONSTANT,
            cv::Scalar(0.0));
  dense_stereo_internal::RectifyMaps(right, stereo.R2, stereo.rectified, &right_x, &right_y);
  const int sign = stereo.mirrored ? 1 : -1;
  // A rectified pixel's ray r_L = R1^T K_rect^-1 (u, v, 1); at the left depth z_L its rectified
  // depth is z_L / r_L.z, and its disparity f B r_L.z / z_L.
  const Eigen::Matrix3d back = stereo.R1.transpose() * stereo.rectified.Matrix().inverse();
  cv::Mat out(z_left.size(), CV_32FC1, cv::Scalar(-1.0f));
  const double fb = stereo.focal_px * stereo.baseline_m;
  for (int v = 0; v < out.rows; ++v) {
    const float* z = z_left.ptr<float>(v);
    float* d = out.ptr<float>(v);
    for (int u = 0; u < out.cols; ++u) {
      if (!(z[u] > 0)) continue;
      const double ray_z = back.row(2).dot(Eigen::Vector3d(u, v, 1.0));
      if (!(ray_z > 0)) continue;
      const double disparity = fb * ray_z / z[u];
      const int ur = static_cast<int>(std::lround(u + sign * disparity));
      if (ur < 0 || ur >= right_x.cols) continue;
      const float sx = right_x.at<float>(v, ur), sy = right_y.at<float>(v, ur);
      const auto& rin = right.intrinsics();
      if (sx < 0 || sy < 0 || sx > rin.width() - 1 || sy > rin.height() - 1) continue;
      d[u] = static_cast<float>(disparity);
    }
  }
  return FloatImage(out);
}

StereoScore ScoreDisparity(const StereoDepth& stereo, const Image& truth_disparity,
                           const std::vector<double>& range_edges_m, int border_px) {
  if (truth_disparity.format() != PixelFormat::kFloat32 ||
      truth_disparity.width() != stereo.disparity.width() ||
      truth_disparity.height() != stereo.disparity.height()) {
    throw InvalidArgument(
        "ScoreDisparity: the true disparity must be float32 of the rectified "
        "size");
  }
  StereoScore score;
  score.range_edges_m = range_edges_m;
  const std::size_t bins = range_edges_m.size() > 1 ? range_edges_m.size() - 1 : 0;
  std::vector<double> sums(bins, 0.0);
  score.range_pixels.assign(bins, 0);
  const cv::Mat truth = WrapFloat(truth_disparity);
  const cv::Mat estimate = WrapFloat(stereo.disparity);
  const double fb = stereo.focal_px * stereo.baseline_m;
  int64_t bad1 = 0, bad2 = 0;
  double sum_sq = 0.0;
  for (int v = border_px; v < truth.rows - border_px; ++v) {
    for (int u = border_px; u < truth.cols - border_px; ++u) {
      const float t = truth.at<float>(v, u);
      if (!(t > 0)) continue;
      ++score.truth_pixels;
      const float e = estimate.at<float>(v, u);
      if (!(e > 0)) continue;
      ++score.matched_pixels;
      const double error = std::abs(e - t);
      bad1 += error > 1.0;
      bad2 += error > 2.0;
      sum_sq += error * error;
      const double z_true = fb / t;
      for (std::size_t b = 0; b < bins && error <= 2.0; ++b) {
        if (z_true >= range_edges_m[b] && z_true < range_edges_m[b + 1]) {
          const double dz = fb / e - z_true;
          sums[b] += dz * dz;
          ++score.range_pixels[b];
        }
      }
    }
  }
  if (score.truth_pixels > 0) {
    score.density = static_cast<double>(score.matched_pixels) / score.truth_pixels;
  }
  if (score.matched_pixels > 0) {
    score.bad_1px = static_cast<double>(bad1) / score.matched_pixels;
    score.bad_2px = static_cast<double>(bad2) / score.matched_pixels;
    score.disparity_rms_px = std::sqrt(sum_sq / score.matched_pixels);
  }
  for (std::size_t b = 0; b < bins; ++b) {
    score.depth_rms_m.push_back(score.range_pixels[b] > 0
                                    ? std::sqrt(sums[b] / score.range_pixels[b])
                                    : std::numeric_limits<double>::quiet_NaN());
  }
  return score;
}

std::vector<Eigen::Vector3d> WorldPoints(const StereoDepth& stereo, int stride,
                                         double min_confidence) {
  std::vector<Eigen::Vector3d> points;
  const cv::Mat depth = WrapFloat(stereo.depth);
  const cv::Mat confidence = WrapFloat(stereo.confidence);
  const Eigen::Matrix3d K_inv = stereo.rectified.Matrix().inverse();
  const int step = std::max(1, stride);
  for (int v = 0; v < depth.rows; v += step) {
    for (int u = 0; u < depth.cols; u += step) {
      const float z = depth.at<float>(v, u);
      if (!(z > 0) || confidence.at<float>(v, u) < min_confidence) continue;
      points.push_back(stereo.X_WR * (z * (K_inv * Eigen::Vector3d(u, v, 1.0))));
    }
  }
  return points;
}

}  // namespace saccade::vision
