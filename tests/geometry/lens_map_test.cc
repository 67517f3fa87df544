// MakeLensMap against OpenCV 4.6 as the reference: every pixel's map entry, taken back through
// its source view (R_CV K_view^-1 [x y 1]), must project with cv::projectPoints or
// cv::fisheye::projectPoints onto that pixel's centre.
//
// The map stores floats, so an entry is the exact source point rounded to float: at source
// coordinates below 4096 that moves it by up to 2^-13 px. Each check is therefore made twice:
// - "double": the ray of the pixel (CameraModel::Unproject, itself tested against OpenCV in
//   camera_model_test) projected into the view in double precision must round to the stored
//   entry (|difference| <= half a float ulp), and that double source point must come back onto
//   the pixel centre through OpenCV within kRoundTripTolerancePx = 1e-6 px;
// - "float": the stored entry itself, through OpenCV, must come back within the float rounding
//   bound kFloatMapTolerancePx.
//
// OpenCV 4.6's cv::fisheye::projectPoints computes x = X/Z and theta = atan(|x|), so a ray
// beyond 90 degrees (Z < 0) comes out mirrored through the principal point at 180 - theta
// (checked by FisheyeOpenCvMirrorsRaysBeyond90Degrees below). Such rays are compared with the
// Kannala-Brandt formula written out in this file (KannalaBrandtPixel), not with OpenCV.

#include "saccade/geometry/lens_map.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <numbers>
#include <opencv2/calib3d.hpp>
#include <optional>
#include <string>
#include <vector>

#include "saccade/core/error.h"

namespace saccade::geometry {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

// The contract of the brief for a double-precision source point: back on its pixel centre
// through OpenCV. Measured values are ~1e-10 px (Newton stops at 1e-14 normalized).
constexpr double kRoundTripTolerancePx = 1e-6;
// A float entry below 4096 px is within 2^-13 = 1.2e-4 px of the exact source point in x and
// in y; an output pixel step spans at least one source pixel where min_scale >= 1 (the source
// is never magnified), so the pixel moves by at most sqrt(2) * 1.2e-4 = 1.7e-4 px; 2e-4 px.
constexpr double kFloatMapTolerancePx = 2e-4;
// The double source point is computed in the test in another order of operations than in
// MakeLensMap (K_view * p vs s * (K p) + c): ~1e-12 px apart before rounding to float.
constexpr double kDoubleVsFloatSlackPx = 1e-9;
// The largest angle from the test's own bisection on theta_d(theta) vs MakeLensMap's Newton:
// both converge to ~1e-15 rad; 1e-9 rad as the brief asks.
constexpr double kMaxAngleTolerance = 1e-9;
// s = 1 / smallest singular value, hence min_scale = s * smallest = 1 up to rounding.
constexpr double kChosenScaleTolerance = 1e-12;
// The test's own central differences of the float map: float rounding (2 * 1.2e-4 px over a
// 2 px step, 1.2e-4 relative) plus the truncation error of the differences: 1e-3.
constexpr double kMapJacobianTolerance = 1e-3;
// "No supersampling needed" for a barrel lens: s within 1e-3 of 1 (see the barrel test).
constexpr double kNearlyOne = 1e-3;
// Float rounding of the stored source points when checking that they keep the margin.
constexpr double kMarginSlackPx = 1e-3;

struct Lens {
  std::string name;
  Intrinsics K;
  DistortionModel model;
  std::vector<double> coefficients;  // OpenCV's order and count

  CameraModel Camera() const {
    return CameraModel(K, Distortion::FromCoefficients(model, coefficients));
  }
};

// theta_d(theta) of Kannala-Brandt, written out independently of distortion.cc.
double ThetaD(const std::vector<double>& k, double theta) {
  const double t2 = theta * theta;
  return theta * (1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))));
}

// theta for theta_d by bisection on [0, pi] (theta_d increasing there for the lenses below).
double ThetaOf(const std::vector<double>& k, double theta_d) {
  double lo = 0.0, hi = std::numbers::pi;
  for (int i = 0; i < 200 && hi - lo > 0.0; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid == lo || mid == hi) break;
    (ThetaD(k, mid) < theta_d ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Distorted normalized coordinates of a pixel through K^-1 (skew included), written out.
Vector2d Normalized(const Intrinsics& K, double u, double v) {
  const double yd = (v - K.cy()) / K.fy();
  return {(u - K.cx() - K.skew() * yd) / K.fx(), yd};
}

// The pixel of a ray through the Kannala-Brandt model for any angle up to 180 degrees: the
// formula of cv::fisheye::projectPoints with theta = atan2(|(X, Y)|, Z) in place of atan(r).
Vector2d KannalaBrandtPixel(const Lens& lens, const Vector3d& ray) {
  const double rho = std::hypot(ray.x(), ray.y());
  const double theta = std::atan2(rho, ray.z());
  const double scale = ThetaD(lens.coefficients, theta) / rho;
  const double xd = ray.x() * scale, yd = ray.y() * scale;
  return {lens.K.fx() * (xd + lens.K.skew() / lens.K.fx() * yd) + lens.K.cx(),
          lens.K.fy() * yd + lens.K.cy()};
}

// OpenCV's pixels of rays (all with z > 0 for the fisheye model). cv::projectPoints reads no
// skew from its matrix (the radtan lenses here have none); the fisheye model takes
// alpha = skew / fx.
std::vector<Vector2d> OpenCvProject(const Lens& lens, const std::vector<Vector3d>& rays) {
  std::vector<Vector2d> out;
  if (rays.empty()) return out;
  std::vector<cv::Point3d> object;
  object.reserve(rays.size());
  for (const Vector3d& p : rays) object.emplace_back(p.x(), p.y(), p.z());
  std::vector<cv::Point2d> image;
  const cv::Vec3d zero(0.0, 0.0, 0.0);
  const cv::Matx33d K(lens.K.fx(), 0.0, lens.K.cx(), 0.0, lens.K.fy(), lens.K.cy(), 0, 0, 1);
  if (lens.model == DistortionModel::kFisheye) {
    cv::fisheye::projectPoints(object, image, zero, zero, K, lens.coefficients,
                               lens.K.skew() / lens.K.fx());
  } else {
    EXPECT_EQ(lens.K.skew(), 0.0) << "cv::projectPoints has no skew";
    cv::projectPoints(object, zero, zero, K, lens.coefficients, image);
  }
  out.reserve(image.size());
  for (const cv::Point2d& p : image) out.emplace_back(p.x, p.y);
  return out;
}

// The ray of source point (x, y) of a view: R_CV K_view^-1 [x y 1].
Vector3d SourceRay(const SourceView& view, double x, double y) {
  return view.R_CV * (view.intrinsics.Matrix().inverse() * Vector3d(x, y, 1.0));
}

// Half the spacing of floats at |x| (the largest rounding error of storing x as float).
double HalfFloatUlp(double x) {
  const float f = static_cast<float>(std::abs(x));
  return 0.5 * (std::nextafter(f, std::numeric_limits<float>::infinity()) - f);
}

struct RoundTrip {
  double worst_double_px = 0.0;
  double worst_float_px = 0.0;
  int64_t checked = 0;
  int64_t beyond_90 = 0;  // rays with z <= 0, checked against KannalaBrandtPixel
};

// Checks every pixel of the map (see the file comment) and returns the worst errors.
RoundTrip CheckRoundTrip(const Lens& lens, const LensMap& map) {
  const CameraModel camera = lens.Camera();
  const Intrinsics& K = lens.K;
  EXPECT_EQ(map.width, K.width());
  EXPECT_EQ(map.height, K.height());
  EXPECT_EQ(map.map.size(), 3u * K.width() * K.height());
  std::vector<Vector3d> rays_double, rays_float;
  std::vector<Vector2d> targets;
  std::vector<Vector3d> behind_double, behind_float;
  std::vector<Vector2d> behind_targets;
  int64_t invalid = 0;
  for (int v = 0; v < K.height(); ++v) {
    for (int u = 0; u < K.width(); ++u) {
      const Eigen::Vector3f entry = map.At(u, v);
      const std::optional<Vector3d> ray = camera.Unproject(Vector2d(u, v));
      if (entry.z() < 0.0f) {
        ++invalid;
        EXPECT_EQ(entry.z(), -1.0f);
        EXPECT_EQ(entry.x(), 0.0f);
        EXPECT_EQ(entry.y(), 0.0f);
        EXPECT_FALSE(ray.has_value()) << "pixel " << u << " " << v << " has a ray";
        continue;
      }
      if (!ray) {
        ADD_FAILURE() << "pixel " << u << " " << v << " has no ray but a map entry";
        continue;
      }
      const int k = static_cast<int>(entry.z());
      EXPECT_EQ(static_cast<float>(k), entry.z());
      if (k < 0 || k >= static_cast<int>(map.views.size())) {
        ADD_FAILURE() << "view " << k << " out of range at " << u << " " << v;
        continue;
      }
      const SourceView& view = map.views[k];
      if (map.kind == LensMap::Kind::kCube) {
        // The ray belongs to the face whose axis has its largest component.
        EXPECT_GE(view.R_CV.col(2).dot(*ray), ray->cwiseAbs().maxCoeff() - 1e-15);
      }
      // The double source point of the pixel's ray, and its float rounding.
      const Vector3d p_V = view.R_CV.transpose() * *ray;
      if (!(p_V.z() > 0.0)) {
        ADD_FAILURE() << "pixel " << u << " " << v << ": ray behind its view";
        continue;
      }
      const Vector3d h = view.intrinsics.Matrix() * (p_V / p_V.z());
      EXPECT_LE(std::abs(h.x() - entry.x()), HalfFloatUlp(h.x()) + kDoubleVsFloatSlackPx);
      EXPECT_LE(std::abs(h.y() - entry.y()), HalfFloatUlp(h.y()) + kDoubleVsFloatSlackPx);
      const Vector3d ray_double = SourceRay(view, h.x(), h.y());
      const Vector3d ray_float = SourceRay(view, entry.x(), entry.y());
      if (lens.model == DistortionModel::kFisheye && !(ray_double.z() > 0.0)) {
        behind_double.push_back(ray_double);
        behind_float.push_back(ray_float);
        behind_targets.emplace_back(u, v);
      } else {
        rays_double.push_back(ray_double);
        rays_float.push_back(ray_float);
        targets.emplace_back(u, v);
      }
    }
  }
  EXPECT_EQ(invalid, map.invalid_pixels);

  RoundTrip result;
  const std::vector<Vector2d> cv_double = OpenCvProject(lens, rays_double);
  const std::vector<Vector2d> cv_float = OpenCvProject(lens, rays_float);
  for (size_t i = 0; i < targets.size(); ++i) {
    result.worst_double_px = std::max(result.worst_double_px, (cv_double[i] - targets[i]).norm());
    result.worst_float_px = std::max(result.worst_float_px, (cv_float[i] - targets[i]).norm());
  }
  for (size_t i = 0; i < behind_targets.size(); ++i) {
    const Vector2d& target = behind_targets[i];
    result.worst_double_px = std::max(result.worst_double_px,
                                      (KannalaBrandtPixel(lens, behind_double[i]) - target).norm());
    result.worst_float_px = std::max(result.worst_float_px,
                                     (KannalaBrandtPixel(lens, behind_float[i]) - target).norm());
  }
  result.checked = static_cast<int64_t>(targets.size() + behind_targets.size());
  result.beyond_90 = static_cast<int64_t>(behind_targets.size());
  EXPECT_LE(result.worst_double_px, kRoundTripTolerancePx);
  if (map.min_scale >= 1.0) {
    EXPECT_LE(result.worst_float_px, kFloatMapTolerancePx);
  }
  std::printf(
      "[ measured ] %s: %lld pixels (%lld beyond 90 deg), worst round trip %.3g px (double), "
      "%.3g px (float map); min_scale %.6f max_scale %.6f; %zu view(s) %d x %d, fx %.3f\n",
      lens.name.c_str(), static_cast<long long>(result.checked),
      static_cast<long long>(result.beyond_90), result.worst_double_px, result.worst_float_px,
      map.min_scale, map.max_scale, map.views.size(), map.views[0].intrinsics.width(),
      map.views[0].intrinsics.height(), map.views[0].intrinsics.fx());
  return result;
}

// Every stored source point keeps the margin from the view's border; for kPinhole the box is
// also tight (at most one pixel of slack from rounding the side up).
void ExpectMarginKept(const LensMap& map, int margin) {
  std::vector<Vector2d> lo(map.views.size(), Vector2d::Constant(1e30));
  std::vector<Vector2d> hi(map.views.size(), Vector2d::Constant(-1e30));
  for (int v = 0; v < map.height; ++v) {
    for (int u = 0; u < map.width; ++u) {
      const Eigen::Vector3f e = map.At(u, v);
      if (e.z() < 0.0f) continue;
      const int k = static_cast<int>(e.z());
      lo[k] = lo[k].cwiseMin(e.head<2>().cast<double>());
      hi[k] = hi[k].cwiseMax(e.head<2>().cast<double>());
    }
  }
  for (size_t k = 0; k < map.views.size(); ++k) {
    const Intrinsics& view = map.views[k].intrinsics;
    const Vector2d side(view.width(), view.height());
    // kPinhole: -0.5 + margin <= x <= side - 0.5 - margin; a cube face keeps its 90-degree
    // square (normalized +-1) between margin and side - 1 - margin.
    const double low = map.kind == LensMap::Kind::kCube ? margin : margin - 0.5;
    for (int a = 0; a < 2; ++a) {
      EXPECT_GE(lo[k][a], low - kMarginSlackPx) << "view " << k << " axis " << a;
      EXPECT_LE(hi[k][a], side[a] - 1.0 - low + kMarginSlackPx) << "view " << k << " axis " << a;
      if (map.kind == LensMap::Kind::kPinhole) {
        const double slack = (lo[k][a] - low) + (side[a] - 1.0 - low - hi[k][a]);
        EXPECT_LT(slack, 1.0 + kMarginSlackPx) << "axis " << a << ": the view is not tight";
      }
    }
  }
}

// Smallest singular value of the float map's own central differences over pixels whose four
// neighbours lie in the same view: an independent check of min_scale.
double MapMinScale(const LensMap& map) {
  double smallest = 1e30;
  for (int v = 1; v + 1 < map.height; ++v) {
    for (int u = 1; u + 1 < map.width; ++u) {
      const Eigen::Vector3f c = map.At(u, v), l = map.At(u - 1, v), r = map.At(u + 1, v),
                            t = map.At(u, v - 1), b = map.At(u, v + 1);
      if (c.z() < 0.0f || l.z() != c.z() || r.z() != c.z() || t.z() != c.z() || b.z() != c.z())
        continue;
      Eigen::Matrix2d J;
      J.col(0) = 0.5 * (r - l).head<2>().cast<double>();
      J.col(1) = 0.5 * (b - t).head<2>().cast<double>();
      const Eigen::JacobiSVD<Eigen::Matrix2d> svd(J);
      smallest = std::min(smallest, svd.singularValues()(1));
    }
  }
  return smallest;
}

// Largest angle to the axis over the image, from the four corner pixels (the farthest from the
// principal point in normalized coordinates, where theta_d and so theta is largest).
double ExpectedFisheyeMaxAngle(const Lens& lens) {
  const double w = lens.K.width() - 1.0, h = lens.K.height() - 1.0;
  double theta_d = 0.0;
  for (const Vector2d& corner : {Vector2d(0, 0), Vector2d(w, 0), Vector2d(0, h), Vector2d(w, h)})
    theta_d = std::max(theta_d, Normalized(lens.K, corner.x(), corner.y()).norm());
  return ThetaOf(lens.coefficients, theta_d);
}

bool HasFace(const LensMap& map, const Vector3d& axis) {
  for (const SourceView& view : map.views) {
    if ((view.R_CV.col(2) - axis).norm() == 0.0) return true;
  }
  return false;
}

// The cube's faces are exactly those that some pixel's ray uses (its largest component), in
// the order +z, -z, +x, -x, +y, -y.
void ExpectFacesOfRays(const Lens& lens, const LensMap& map) {
  const std::vector<Vector3d> order = {{0, 0, 1},  {0, 0, -1}, {1, 0, 0},
                                       {-1, 0, 0}, {0, 1, 0},  {0, -1, 0}};
  std::vector<bool> used(6, false);
  const CameraModel camera = lens.Camera();
  for (int v = 0; v < lens.K.height(); ++v) {
    for (int u = 0; u < lens.K.width(); ++u) {
      const std::optional<Vector3d> ray = camera.Unproject(Vector2d(u, v));
      if (!ray) continue;
      for (int face = 0; face < 6; ++face) {
        if (order[face].dot(*ray) == ray->cwiseAbs().maxCoeff()) {
          used[face] = true;
          break;
        }
      }
    }
  }
  std::vector<Vector3d> expected;
  for (int face = 0; face < 6; ++face) {
    if (used[face]) expected.push_back(order[face]);
  }
  ASSERT_EQ(map.views.size(), expected.size());
  for (size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(map.views[k].R_CV.col(2), expected[k]) << "view " << k;
  }
}

// --- Lenses -------------------------------------------------------------------------------

// Strong barrel: ~30% at the corners, rays to 52 degrees.
Lens BarrelLens() {
  return {"radtan barrel",
          Intrinsics(1024, 768, 800.0, 795.0, 517.3, 379.6),
          DistortionModel::kRadialTangential,
          {-0.35, 0.12, 0.001, -0.0015, -0.02}};
}

// Pincushion: the image magnifies towards the corners, so the source must be finer.
Lens PincushionLens() {
  return {"radtan pincushion",
          Intrinsics(1024, 768, 800.0, 795.0, 505.1, 390.2),
          DistortionModel::kRadialTangential,
          {0.25, 0.05, -0.0008, 0.0006, 0.01}};
}

// Rational model (k4..k6 non-zero) as calibrated for wide-angle lenses.
Lens RationalLens() {
  return {"radtan rational",
          Intrinsics(1024, 768, 800.0, 780.0, 530.3, 370.8),
          DistortionModel::kRadialTangential,
          {2.0, 0.5, 0.0005, -0.0011, 0.01, 2.4, 1.1, 0.05}};
}

// A moderate fisheye: 52 degrees in the corners (104 degree diagonal field of view), skewed.
Lens ModerateFisheyeLens() {
  return {"fisheye moderate",
          Intrinsics(1024, 768, 700.0, 697.0, 515.8, 381.2, 1.5),
          DistortionModel::kFisheye,
          {0.05, -0.02, 0.005, -0.0005}};
}

const std::vector<double> kWideFisheyeCoefficients = {-0.01, 0.002, -0.0003, 0.00002};

// 180 degrees across the width and height: theta = 90 degrees at the centres of the left and
// top edge pixels (about 127 degrees in the corners, so the back face is used there).
Lens Fisheye180Lens() {
  const double f = 511.5 / ThetaD(kWideFisheyeCoefficients, 0.5 * std::numbers::pi);
  return {"fisheye 180", Intrinsics(1024, 1024, f, f, 511.5, 511.5), DistortionModel::kFisheye,
          kWideFisheyeCoefficients};
}

// 190 degrees across the width: theta = 95 degrees at the centre of the left edge pixels;
// off-centre principal point, fx != fy and skew (OpenCV's alpha).
Lens Fisheye190Lens() {
  const double f = 641.3 / ThetaD(kWideFisheyeCoefficients, 95.0 * std::numbers::pi / 180.0);
  return {"fisheye 190", Intrinsics(1280, 960, f, 0.997 * f, 641.3, 478.9, 0.8),
          DistortionModel::kFisheye, kWideFisheyeCoefficients};
}

// An equidistant lens (zero coefficients) seeing 200 degrees off-axis in the corners: pixels
// beyond 180 degrees have no ray, and the back face is used.
Lens EquidistantBeyond180Lens() {
  return {"fisheye equidistant 400", Intrinsics(1024, 1024, 200.0, 200.0, 511.5, 511.5),
          DistortionModel::kFisheye, std::vector<double>(4, 0.0)};
}

// --- Tests --------------------------------------------------------------------------------

TEST(LensMapRadTan, BarrelIsOnePinholeViewThatRoundTripsThroughCvProjectPoints) {
  const Lens lens = BarrelLens();
  const LensMapOptions options;
  const LensMap map = MakeLensMap(lens.Camera(), options);
  ASSERT_EQ(map.kind, LensMap::Kind::kPinhole);
  ASSERT_EQ(map.views.size(), 1u);
  EXPECT_EQ(map.views[0].R_CV, Matrix3d::Identity());
  EXPECT_EQ(map.invalid_pixels, 0);
  // Barrel distortion stretches the undistorted image, so the camera's own focal length almost
  // suffices; near the centre, where the radial terms vanish, the tangential terms (p1, p2)
  // still shrink some directions by ~3e-5, hence s slightly above 1.
  const double s = map.views[0].intrinsics.fx() / lens.K.fx();
  EXPECT_GE(s, 1.0);
  EXPECT_LT(s, 1.0 + kNearlyOne);
  EXPECT_NEAR(map.views[0].intrinsics.fy(), s * lens.K.fy(), 1e-12);
  EXPECT_GE(map.min_scale, 1.0 - kChosenScaleTolerance);
  EXPECT_GT(map.max_scale, 1.2);
  EXPECT_GT(map.views[0].intrinsics.width(), lens.K.width());
  EXPECT_GT(map.max_angle, 0.8);
  EXPECT_LT(map.max_angle, options.max_pinhole_angle);
  CheckRoundTrip(lens, map);
  ExpectMarginKept(map, options.margin_px);
  EXPECT_GE(MapMinScale(map), 1.0 - kMapJacobianTolerance);
}

TEST(LensMapRadTan, PincushionSupersamplesSoThatNoPixelMagnifiesTheSource) {
  const Lens lens = PincushionLens();
  const LensMapOptions options;
  const LensMap map = MakeLensMap(lens.Camera(), options);
  ASSERT_EQ(map.kind, LensMap::Kind::kPinhole);
  ASSERT_EQ(map.views.size(), 1u);
  EXPECT_EQ(map.invalid_pixels, 0);
  const Intrinsics& view = map.views[0].intrinsics;
  const double s = view.fx() / lens.K.fx();
  EXPECT_GT(s, 1.1);
  EXPECT_LT(s, options.max_supersampling);
  EXPECT_NEAR(view.fy() / lens.K.fy(), s, 1e-15 * s) << "fx/fy ratio kept";
  EXPECT_EQ(view.skew(), 0.0);
  EXPECT_NEAR(map.min_scale, 1.0, kChosenScaleTolerance);
  CheckRoundTrip(lens, map);
  ExpectMarginKept(map, options.margin_px);
  EXPECT_GE(MapMinScale(map), 1.0 - kMapJacobianTolerance);
}

TEST(LensMapRadTan, RationalModelWithK4K5K6RoundTrips) {
  const Lens lens = RationalLens();
  const LensMap map = MakeLensMap(lens.Camera());
  ASSERT_EQ(map.kind, LensMap::Kind::kPinhole);
  EXPECT_EQ(map.invalid_pixels, 0);
  EXPECT_GE(map.min_scale, 1.0 - kChosenScaleTolerance);
  CheckRoundTrip(lens, map);
  ExpectMarginKept(map, LensMapOptions().margin_px);
}

TEST(LensMapRadTan, SupersamplingIsCappedByMaxSupersampling) {
  const Lens lens = PincushionLens();
  const LensMap free = MakeLensMap(lens.Camera());
  const double s_needed = free.views[0].intrinsics.fx() / lens.K.fx();
  ASSERT_GT(s_needed, 1.05);
  LensMapOptions options;
  options.max_supersampling = 1.05;
  const LensMap map = MakeLensMap(lens.Camera(), options);
  ASSERT_EQ(map.kind, LensMap::Kind::kPinhole);
  EXPECT_DOUBLE_EQ(map.views[0].intrinsics.fx(), 1.05 * lens.K.fx());
  // The cap leaves magnification: min_scale scales with the focal length.
  EXPECT_NEAR(map.min_scale, 1.05 / s_needed, kChosenScaleTolerance);
  EXPECT_NEAR(map.max_scale, free.max_scale * 1.05 / s_needed, kChosenScaleTolerance);
  CheckRoundTrip(lens, map);
}

TEST(LensMapRadTan, MaxSourceSideForcesTheCube) {
  const Lens lens = BarrelLens();
  const LensMap wide = MakeLensMap(lens.Camera());
  ASSERT_EQ(wide.kind, LensMap::Kind::kPinhole);
  ASSERT_GT(wide.views[0].intrinsics.width(), 1024);

  LensMapOptions options;
  options.max_source_side = 1024;
  const LensMap map = MakeLensMap(lens.Camera(), options);
  ASSERT_EQ(map.kind, LensMap::Kind::kCube);
  ExpectFacesOfRays(lens, map);
  for (const SourceView& view : map.views) {
    EXPECT_EQ(view.intrinsics.width(), 1024) << "capped";
    EXPECT_EQ(view.intrinsics.width(), view.intrinsics.height());
  }
  EXPECT_EQ(map.views[0].R_CV, Matrix3d::Identity()) << "+z first";
  EXPECT_LT(map.min_scale, 1.0) << "the cap leaves magnification";
  EXPECT_DOUBLE_EQ(map.max_angle, wide.max_angle);
  CheckRoundTrip(lens, map);
  ExpectMarginKept(map, options.margin_px);
}

TEST(LensMapRadTan, MaxPinholeAngleSendsNarrowerLensesToTheCube) {
  const Lens lens = BarrelLens();
  LensMapOptions options;
  options.max_pinhole_angle = 0.5;
  const LensMap map = MakeLensMap(lens.Camera(), options);
  ASSERT_EQ(map.kind, LensMap::Kind::kCube);
  ExpectFacesOfRays(lens, map);
  EXPECT_GE(map.min_scale, 1.0 - kChosenScaleTolerance);
  CheckRoundTrip(lens, map);
  ExpectMarginKept(map, options.margin_px);
  EXPECT_GE(MapMinScale(map), 1.0 - kMapJacobianTolerance);
}

TEST(LensMapFisheye, OpenCvMirrorsRaysBeyond90Degrees) {
  // Documents why rays beyond 90 degrees are checked against KannalaBrandtPixel: OpenCV 4.6
  // divides by Z and takes atan(r), so (X, Y, -Z) lands where the mirrored ray (-X, -Y, Z)
  // does.
  const Lens lens = Fisheye190Lens();
  const Vector3d behind = Vector3d(0.6, 0.8, -0.1).normalized();
  const Vector3d mirrored(-behind.x(), -behind.y(), -behind.z());
  const Vector3d front = Vector3d(0.6, 0.8, 0.1).normalized();
  const std::vector<Vector2d> cv_front = OpenCvProject(lens, {front});
  const std::vector<Vector2d> cv_behind = [&] {
    std::vector<cv::Point3d> object = {{behind.x(), behind.y(), behind.z()}};
    std::vector<cv::Point2d> image;
    const cv::Matx33d K(lens.K.fx(), 0.0, lens.K.cx(), 0.0, lens.K.fy(), lens.K.cy(), 0, 0, 1);
    cv::fisheye::projectPoints(object, image, cv::Vec3d::zeros(), cv::Vec3d::zeros(), K,
                               lens.coefficients, lens.K.skew() / lens.K.fx());
    return std::vector<Vector2d>{{image[0].x, image[0].y}};
  }();
  const std::vector<Vector2d> cv_mirrored = OpenCvProject(lens, {mirrored});
  EXPECT_LT((cv_behind[0] - cv_mirrored[0]).norm(), 1e-9);
  EXPECT_GT((cv_behind[0] - KannalaBrandtPixel(lens, behind)).norm(), 100.0);
  // In front, the written-out formula is OpenCV's.
  EXPECT_LT((cv_front[0] - KannalaBrandtPixel(lens, front)).norm(), 1e-9);
}

TEST(LensMapFisheye, Fisheye180UsesAllSixCubeFacesAndRoundTrips) {
  const Lens lens = Fisheye180Lens();
  const LensMapOptions options;
  const LensMap map = MakeLensMap(lens.Camera(), options);
  ASSERT_EQ(map.kind, LensMap::Kind::kCube);
  EXPECT_EQ(map.invalid_pixels, 0);
  EXPECT_NEAR(map.max_angle, ExpectedFisheyeMaxAngle(lens), kMaxAngleTolerance);
  // All six faces: the corners see 127 degrees off-axis along the diagonals, beyond the
  // 125.3 degrees (180 - atan(sqrt 2)) where the back face begins there.
  ExpectFacesOfRays(lens, map);
  ASSERT_EQ(map.views.size(), 6u);
  const std::vector<Vector3d> axes = {{0, 0, 1},  {0, 0, -1}, {1, 0, 0},
                                      {-1, 0, 0}, {0, 1, 0},  {0, -1, 0}};
  for (size_t k = 0; k < axes.size(); ++k) {
    const Matrix3d& R = map.views[k].R_CV;
    EXPECT_EQ(R.col(2), axes[k]) << "face " << k;
    EXPECT_EQ(R.transpose() * R, Matrix3d::Identity());
    EXPECT_EQ(R.determinant(), 1.0) << "right-handed";
    const Intrinsics& K = map.views[k].intrinsics;
    EXPECT_EQ(K, map.views[0].intrinsics) << "all faces alike";
    EXPECT_EQ(K.width(), K.height());
    EXPECT_EQ(K.cx(), 0.5 * (K.width() - 1));
    EXPECT_EQ(K.fx(), K.cx() - options.margin_px);
  }
  // Side and back faces keep "down" (y_V = y_C); the down face looks with its top forward.
  EXPECT_EQ(map.views[1].R_CV.col(1), Vector3d(0, 1, 0));
  EXPECT_EQ(map.views[2].R_CV.col(1), Vector3d(0, 1, 0));
  EXPECT_EQ(map.views[4].R_CV.col(1), Vector3d(0, 0, -1));
  EXPECT_GE(map.min_scale, 1.0 - kChosenScaleTolerance);
  const RoundTrip trip = CheckRoundTrip(lens, map);
  EXPECT_GT(trip.beyond_90, 100000);
  ExpectMarginKept(map, options.margin_px);
  EXPECT_GE(MapMinScale(map), 1.0 - kMapJacobianTolerance);
}

TEST(LensMapFisheye, Fisheye190HasNoBackFaceAndRoundTrips) {
  const Lens lens = Fisheye190Lens();
  const LensMapOptions options;
  const LensMap map = MakeLensMap(lens.Camera(), options);
  ASSERT_EQ(map.kind, LensMap::Kind::kCube);
  EXPECT_EQ(map.invalid_pixels, 0);
  const double expected = ExpectedFisheyeMaxAngle(lens);
  EXPECT_GT(expected, 95.0 * std::numbers::pi / 180.0);
  EXPECT_NEAR(map.max_angle, expected, kMaxAngleTolerance);
  ExpectFacesOfRays(lens, map);
  EXPECT_EQ(map.views.size(), 5u);
  EXPECT_FALSE(HasFace(map, Vector3d(0, 0, -1)));
  // The face focal: as fine as the lens needs (min_scale 1), within the supersampling cap.
  const double f = map.views[0].intrinsics.fx();
  EXPECT_GE(f, lens.K.fx());
  EXPECT_LE(f, options.max_supersampling * lens.K.fx());
  EXPECT_GE(map.min_scale, 1.0 - kChosenScaleTolerance);
  // S is the smallest size with min_scale >= 1: one pixel less would magnify somewhere.
  EXPECT_LT(map.min_scale * (f - 0.5) / f, 1.0);
  const RoundTrip trip = CheckRoundTrip(lens, map);
  EXPECT_GT(trip.beyond_90, 1000);
  ExpectMarginKept(map, options.margin_px);
  EXPECT_GE(MapMinScale(map), 1.0 - kMapJacobianTolerance);
}

TEST(LensMapFisheye, BeyondHalfTurnPixelsHaveNoRayAndTheBackFaceIsUsed) {
  const Lens lens = EquidistantBeyond180Lens();
  const LensMap map = MakeLensMap(lens.Camera());
  ASSERT_EQ(map.kind, LensMap::Kind::kCube);
  ExpectFacesOfRays(lens, map);
  EXPECT_EQ(map.views.size(), 6u);
  EXPECT_EQ(map.views[1].R_CV.col(2), Vector3d(0, 0, -1)) << "back face second";
  // Equidistant: theta = theta_d; no ray from theta = 180 degrees on.
  int64_t expected_invalid = 0;
  for (int v = 0; v < lens.K.height(); ++v) {
    for (int u = 0; u < lens.K.width(); ++u)
      expected_invalid += Normalized(lens.K, u, v).norm() >= std::numbers::pi;
  }
  EXPECT_GT(expected_invalid, 0);
  EXPECT_EQ(map.invalid_pixels, expected_invalid);
  EXPECT_LT(map.max_angle, std::numbers::pi);
  EXPECT_GT(map.max_angle, std::numbers::pi - 0.01);
  CheckRoundTrip(lens, map);
  ExpectMarginKept(map, LensMapOptions().margin_px);
}

TEST(LensMapFisheye, ModerateFisheyeIsOnePinholeView) {
  const Lens lens = ModerateFisheyeLens();
  const LensMapOptions options;
  const LensMap map = MakeLensMap(lens.Camera(), options);
  ASSERT_EQ(map.kind, LensMap::Kind::kPinhole);
  EXPECT_NEAR(map.max_angle, ExpectedFisheyeMaxAngle(lens), kMaxAngleTolerance);
  EXPECT_LT(map.max_angle, options.max_pinhole_angle);
  const Intrinsics& view = map.views[0].intrinsics;
  const double s = view.fx() / lens.K.fx();
  EXPECT_NEAR(view.skew(), s * lens.K.skew(), 1e-12) << "skew scaled with the focal";
  EXPECT_GE(map.min_scale, 1.0 - kChosenScaleTolerance);
  CheckRoundTrip(lens, map);
  ExpectMarginKept(map, options.margin_px);
  EXPECT_GE(MapMinScale(map), 1.0 - kMapJacobianTolerance);
}

TEST(LensMapFisheye, ZeroFisheyeIsNotTheIdentity) {
  const Lens lens{"fisheye zero narrow", Intrinsics(640, 480, 900.0, 900.0, 319.5, 239.5),
                  DistortionModel::kFisheye, std::vector<double>(4, 0.0)};
  const LensMap map = MakeLensMap(lens.Camera());
  EXPECT_EQ(map.kind, LensMap::Kind::kPinhole);
  CheckRoundTrip(lens, map);
}

TEST(LensMapIdentity, NoDistortionGivesTheIdentityMap) {
  const Intrinsics K(640, 480, 500.0, 490.0, 300.2, 250.7, 1.3);
  for (const Distortion& distortion :
       {Distortion(), Distortion::RadialTangential(std::vector<double>(5, 0.0))}) {
    const LensMap map = MakeLensMap(CameraModel(K, distortion));
    ASSERT_EQ(map.kind, LensMap::Kind::kIdentity);
    ASSERT_EQ(map.views.size(), 1u);
    EXPECT_EQ(map.views[0].intrinsics, K);
    EXPECT_EQ(map.views[0].R_CV, Matrix3d::Identity());
    EXPECT_EQ(map.invalid_pixels, 0);
    EXPECT_EQ(map.min_scale, 1.0);
    EXPECT_EQ(map.max_scale, 1.0);
    ASSERT_EQ(map.map.size(), 3u * 640 * 480);
    for (int v = 0; v < 480; ++v) {
      for (int u = 0; u < 640; ++u) ASSERT_EQ(map.At(u, v), Eigen::Vector3f(u, v, 0));
    }
    double expected = 0.0;
    for (const Vector2d& c :
         {Vector2d(0, 0), Vector2d(639, 0), Vector2d(0, 479), Vector2d(639, 479)})
      expected = std::max(expected, std::atan(Normalized(K, c.x(), c.y()).norm()));
    EXPECT_NEAR(map.max_angle, expected, kMaxAngleTolerance);
  }
}

TEST(LensMapErrors, InvalidOptionsThrowNamingTheOptionAndValue) {
  struct Case {
    LensMapOptions options;
    std::string name, value;
  };
  std::vector<Case> cases;
  auto add = [&](auto set, std::string name, std::string value) {
    LensMapOptions o;
    set(o);
    cases.push_back({o, std::move(name), std::move(value)});
  };
  add([](LensMapOptions& o) { o.max_pinhole_angle = 0.0; }, "max_pinhole_angle", "0");
  add([](LensMapOptions& o) { o.max_pinhole_angle = 1.6; }, "max_pinhole_angle", "1.6");
  add([](LensMapOptions& o) { o.max_pinhole_angle = std::nan(""); }, "max_pinhole_angle", "nan");
  add([](LensMapOptions& o) { o.max_supersampling = 0.5; }, "max_supersampling", "0.5");
  add([](LensMapOptions& o) { o.max_supersampling = INFINITY; }, "max_supersampling", "inf");
  add([](LensMapOptions& o) { o.max_source_side = 15; }, "max_source_side", "15");
  add([](LensMapOptions& o) { o.margin_px = 0; }, "margin_px", "0");
  add(
      [](LensMapOptions& o) {
        o.max_source_side = 64;
        o.margin_px = 17;
      },
      "margin_px", "17");
  const CameraModel camera = BarrelLens().Camera();
  for (const Case& c : cases) {
    std::string error;
    EXPECT_FALSE(c.options.IsValid(&error)) << c.name;
    EXPECT_NE(error.find(c.name), std::string::npos) << error;
    EXPECT_FALSE(c.options.IsValid(nullptr));
    try {
      MakeLensMap(camera, c.options);
      ADD_FAILURE() << c.name << " " << c.value << " accepted";
    } catch (const InvalidArgument& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind("MakeLensMap: ", 0), 0u) << message;
      EXPECT_NE(message.find(c.name), std::string::npos) << message;
      EXPECT_NE(message.find("got " + c.value), std::string::npos) << message;
    }
  }
  std::string error = "untouched";
  EXPECT_TRUE(LensMapOptions().IsValid(&error));
  EXPECT_EQ(error, "untouched");
}

TEST(LensMapErrors, CameraWithNoRayAnywhereThrows) {
  // Barrel folding back at normalized radius 0.82 (distorted 0.54), with the principal point
  // far left of the image: every pixel lies beyond the fold, where the model has no inverse.
  const CameraModel camera(Intrinsics(320, 240, 800.0, 800.0, -5000.0, 120.0),
                           Distortion::RadialTangential(std::vector<double>{-0.5, 0.0, 0.0, 0.0}));
  try {
    MakeLensMap(camera);
    ADD_FAILURE() << "no exception";
  } catch (const InvalidArgument& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("MakeLensMap: no pixel", 0), 0u) << message;
    EXPECT_NE(message.find("320 x 240"), std::string::npos) << message;
  }
}

TEST(LensMapDeterminism, TwoCallsGiveBitIdenticalMaps) {
  for (const Lens& lens : {Fisheye190Lens(), PincushionLens()}) {
    const LensMap a = MakeLensMap(lens.Camera());
    const LensMap b = MakeLensMap(lens.Camera());
    ASSERT_EQ(a.map.size(), b.map.size());
    EXPECT_EQ(std::memcmp(a.map.data(), b.map.data(), a.map.size() * sizeof(float)), 0);
    ASSERT_EQ(a.views.size(), b.views.size());
    for (size_t k = 0; k < a.views.size(); ++k) {
      EXPECT_EQ(a.views[k].intrinsics, b.views[k].intrinsics);
      EXPECT_EQ(a.views[k].R_CV, b.views[k].R_CV);
    }
    EXPECT_EQ(a.min_scale, b.min_scale);
    EXPECT_EQ(a.max_scale, b.max_scale);
    EXPECT_EQ(a.max_angle, b.max_angle);
  }
}

}  // namespace
}  // namespace saccade::geometry
