// CameraModel against OpenCV 4.6 as the reference: cv::projectPoints, cv::fisheye::projectPoints,
// cv::undistortPoints and cv::fisheye::undistortPoints.

#include "saccade/geometry/camera_model.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <opencv2/calib3d.hpp>
#include <random>
#include <string>
#include <vector>

#include "saccade/geometry/json.h"

namespace saccade::geometry {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// saccade and OpenCV evaluate the same expressions with a few operations in another order
// (X/Z vs X*(1/Z), atan2 vs atan): a few 1e-13 px at 1000 px. 1e-9 px is "to the digit" for any
// use and would still catch any error in the model (a wrong term is > 1e-6 px).
constexpr double kProjectTolerancePx = 1e-9;
// Test points are made from target pixels through OpenCV's own inverse; they must land back on
// them, which proves that the projections cover the whole image, corners included.
constexpr double kCoverageTolerancePx = 1e-6;
// distort(undistort(p)) and the comparison with OpenCV's iterative undistortion: both converge
// to ~1e-11 px; 1e-6 px is the contract of the brief for the invertible region.
constexpr double kRoundTripTolerancePx = 1e-6;
constexpr double kUndistortVsOpenCvPx = 1e-6;
// Angle between the ray of Unproject(Project(p)) and p: Newton stops at 1e-14 normalized.
constexpr double kRayAngleTolerance = 1e-9;
constexpr int kSamples = 3000;

struct Lens {
  std::string name;
  Intrinsics K;
  DistortionModel model;
  std::vector<double> coefficients;  // OpenCV's order and count

  CameraModel Camera() const {
    return CameraModel(K, Distortion::FromCoefficients(model, coefficients));
  }
};

// Off-centre principal point and fx != fy throughout.
const Intrinsics kXga(1024, 768, 800.0, 780.0, 530.3, 370.8);
const Intrinsics kXgaSkewed(1024, 768, 800.0, 780.0, 530.3, 370.8, 3.7);
const Intrinsics kFisheyeK(1280, 1024, 600.0, 596.0, 652.4, 498.1);
const Intrinsics kFisheyeSkewed(1280, 1024, 600.0, 596.0, 652.4, 498.1, 2.1);

std::vector<Lens> RadTanLenses(const Intrinsics& K) {
  return {
      {"none", K, DistortionModel::kNone, {}},
      // ~20% barrel at the corners.
      {"radtan4", K, DistortionModel::kRadialTangential, {-0.30, 0.09, 0.0012, -0.0009}},
      {"radtan5", K, DistortionModel::kRadialTangential, {-0.42, 0.25, -0.0007, 0.0015, -0.06}},
      // Rational model as calibrated for wide-angle lenses: ~25% barrel at the corners.
      {"radtan8",
       K,
       DistortionModel::kRadialTangential,
       {2.0, 0.5, 0.0005, -0.0011, 0.01, 2.4, 1.1, 0.05}},
  };
}

Lens FisheyeLens(const Intrinsics& K) {
  return {"fisheye", K, DistortionModel::kFisheye, {0.05, -0.02, 0.005, -0.0005}};
}

// A lens seeing 136 degrees off-axis in the image corners (272 degree diagonal field of view).
Lens WideFisheyeLens() {
  return {"wide fisheye",
          Intrinsics(1280, 1024, 320.0, 320.0, 641.2, 509.7),
          DistortionModel::kFisheye,
          {0.01, -0.005, 0.001, 0.0}};
}

cv::Matx33d CvMatrix(const Intrinsics& K) {
  return cv::Matx33d(K.fx(), K.skew(), K.cx(), 0.0, K.fy(), K.cy(), 0.0, 0.0, 1.0);
}

// Uniform pixels over the whole image plus its four outer corners and the four corner pixels.
std::vector<Vector2d> PixelsCoveringImage(const Intrinsics& K, int n, unsigned seed) {
  const double w = K.width(), h = K.height();
  std::vector<Vector2d> pixels = {{-0.5, -0.5},       {w - 0.5, -0.5},   {-0.5, h - 0.5},
                                  {w - 0.5, h - 0.5}, {0.0, 0.0},        {w - 1.0, 0.0},
                                  {0.0, h - 1.0},     {w - 1.0, h - 1.0}};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.5, w - 0.5), v(-0.5, h - 0.5);
  for (int i = 0; i < n; ++i) pixels.emplace_back(u(rng), v(rng));
  return pixels;
}

std::vector<cv::Point2d> ToCv(const std::vector<Vector2d>& points) {
  std::vector<cv::Point2d> out;
  for (const Vector2d& p : points) out.emplace_back(p.x(), p.y());
  return out;
}

// Distorted normalized coordinates of pixels, through OpenCV's K^-1 (skew included).
std::vector<cv::Point2d> CvPixelToNormalized(const Intrinsics& K,
                                             const std::vector<Vector2d>& pixels) {
  const cv::Matx33d K_inv = CvMatrix(K).inv();
  std::vector<cv::Point2d> out;
  for (const Vector2d& p : pixels) {
    const cv::Vec3d q = K_inv * cv::Vec3d(p.x(), p.y(), 1.0);
    out.emplace_back(q[0] / q[2], q[1] / q[2]);
  }
  return out;
}

// 3D points whose projections are the given pixels, made with OpenCV's inverse only (so that
// the code under test plays no part in choosing them), at random depths from 0.05 to 50 m.
std::vector<Vector3d> PointsOnPixels(const Lens& lens, const std::vector<Vector2d>& pixels,
                                     unsigned seed) {
  const std::vector<cv::Point2d> distorted = CvPixelToNormalized(lens.K, pixels);
  std::vector<cv::Point2d> undistorted;
  if (lens.model == DistortionModel::kFisheye) {
    cv::fisheye::undistortPoints(
        distorted, undistorted, cv::Matx33d::eye(), lens.coefficients, cv::noArray(), cv::noArray(),
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-14));
  } else {
    cv::undistortPoints(
        distorted, undistorted, cv::Matx33d::eye(), lens.coefficients, cv::noArray(), cv::noArray(),
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 1000, 1e-15));
  }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> depth(0.05, 50.0);
  std::vector<Vector3d> points;
  for (const cv::Point2d& p : undistorted) {
    const double z = depth(rng);
    points.emplace_back(p.x * z, p.y * z, z);
  }
  return points;
}

// OpenCV's pixels for the points. cv::projectPoints reads only fx, fy, cx, cy of its camera
// matrix (no skew), so with skew the reference is cv::projectPoints with an identity camera
// matrix, which gives (xd, yd), followed by K with skew. The fisheye model takes the skew as
// alpha = skew / fx.
std::vector<Vector2d> OpenCvProject(const Lens& lens, const std::vector<Vector3d>& points) {
  std::vector<cv::Point3d> object;
  for (const Vector3d& p : points) object.emplace_back(p.x(), p.y(), p.z());
  std::vector<cv::Point2d> image;
  const cv::Vec3d zero(0.0, 0.0, 0.0);
  std::vector<Vector2d> out;
  if (lens.model == DistortionModel::kFisheye) {
    const cv::Matx33d K(lens.K.fx(), 0.0, lens.K.cx(), 0.0, lens.K.fy(), lens.K.cy(), 0, 0, 1);
    cv::fisheye::projectPoints(object, image, zero, zero, K, lens.coefficients,
                               lens.K.skew() / lens.K.fx());
    for (const cv::Point2d& p : image) out.emplace_back(p.x, p.y);
  } else if (lens.K.skew() == 0.0) {
    cv::projectPoints(object, zero, zero, CvMatrix(lens.K), lens.coefficients, image);
    for (const cv::Point2d& p : image) out.emplace_back(p.x, p.y);
  } else {
    cv::projectPoints(object, zero, zero, cv::Matx33d::eye(), lens.coefficients, image);
    const cv::Matx33d K = CvMatrix(lens.K);
    for (const cv::Point2d& p : image) {
      const cv::Vec3d q = K * cv::Vec3d(p.x, p.y, 1.0);
      out.emplace_back(q[0], q[1]);
    }
  }
  return out;
}

double AngleBetween(const Vector3d& a, const Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

void ExpectProjectMatchesOpenCv(const Lens& lens, unsigned seed) {
  SCOPED_TRACE(lens.name);
  const CameraModel camera = lens.Camera();
  const std::vector<Vector2d> targets = PixelsCoveringImage(lens.K, kSamples, seed);
  const std::vector<Vector3d> points = PointsOnPixels(lens, targets, seed + 1);
  const std::vector<Vector2d> reference = OpenCvProject(lens, points);
  double worst = 0.0, worst_coverage = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    worst_coverage = std::max(worst_coverage, (reference[i] - targets[i]).norm());
    const std::optional<Vector2d> uv = camera.Project(points[i]);
    ASSERT_TRUE(uv.has_value()) << points[i].transpose();
    const double error = (*uv - reference[i]).norm();
    worst = std::max(worst, error);
    EXPECT_LE(error, kProjectTolerancePx)
        << "point " << points[i].transpose() << " saccade " << uv->transpose() << " OpenCV "
        << reference[i].transpose();
  }
  EXPECT_LE(worst_coverage, kCoverageTolerancePx) << "test points do not cover the image";
  std::printf("[ measured ] %s Project vs OpenCV: worst %.3g px (coverage %.3g px)\n",
              lens.name.c_str(), worst, worst_coverage);
}

TEST(CameraModelProject, MatchesCvProjectPointsOverWholeImage) {
  unsigned seed = 100;
  for (const Lens& lens : RadTanLenses(kXga)) ExpectProjectMatchesOpenCv(lens, seed++);
}

TEST(CameraModelProject, WithSkewMatchesCvProjectPointsNormalizedThenSkewedK) {
  unsigned seed = 200;
  for (Lens lens : RadTanLenses(kXgaSkewed)) {
    lens.name += " skewed";
    ExpectProjectMatchesOpenCv(lens, seed++);
  }
}

TEST(CameraModelProject, FisheyeMatchesCvFisheyeProjectPointsWithAlpha) {
  ExpectProjectMatchesOpenCv(FisheyeLens(kFisheyeK), 300);
  Lens skewed = FisheyeLens(kFisheyeSkewed);
  skewed.name += " skewed";
  ExpectProjectMatchesOpenCv(skewed, 301);
}

TEST(CameraModelProject, DistortPixelMatchesCvProjectPointsOfUndistortedPixel) {
  for (const Lens& lens : {RadTanLenses(kXga)[3], FisheyeLens(kFisheyeK)}) {
    SCOPED_TRACE(lens.name);
    const CameraModel camera = lens.Camera();
    // Undistorted pixels (ideal pinhole, same K) over the image and somewhat beyond.
    std::vector<Vector2d> ideal = PixelsCoveringImage(lens.K, kSamples, 400);
    std::vector<Vector3d> points;
    for (const cv::Point2d& p : CvPixelToNormalized(lens.K, ideal))
      points.emplace_back(p.x, p.y, 1);
    const std::vector<Vector2d> reference = OpenCvProject(lens, points);
    for (size_t i = 0; i < ideal.size(); ++i) {
      EXPECT_LE((camera.DistortPixel(ideal[i]) - reference[i]).norm(), kProjectTolerancePx);
    }
  }
}

TEST(CameraModelProject, PinholeAndRadtanCannotImagePointsBehindTheCamera) {
  for (const Lens& lens : RadTanLenses(kXga)) {
    SCOPED_TRACE(lens.name);
    const CameraModel camera = lens.Camera();
    EXPECT_FALSE(camera.Project({0.1, 0.2, -1.0}).has_value());
    EXPECT_FALSE(camera.Project({0.1, 0.2, 0.0}).has_value());
    EXPECT_FALSE(camera.Project({0.0, 0.0, 0.0}).has_value());
    EXPECT_FALSE(camera.Project({std::nan(""), 0.0, 1.0}).has_value());
    EXPECT_TRUE(camera.Project({0.1, 0.2, 1e-3}).has_value());
  }
  const CameraModel fisheye = FisheyeLens(kFisheyeK).Camera();
  EXPECT_FALSE(fisheye.Project({0.0, 0.0, 0.0}).has_value());
  EXPECT_FALSE(fisheye.Project({0.0, 0.0, -1.0}).has_value()) << "straight backward: no pixel";
  EXPECT_TRUE(fisheye.Project({0.3, 0.2, -1.0}).has_value()) << "fisheye images beyond 90 deg";
}

TEST(CameraModelProject, OpticalAxisLandsOnPrincipalPoint) {
  for (const Lens& lens : RadTanLenses(kXgaSkewed)) {
    const std::optional<Vector2d> uv = lens.Camera().Project({0.0, 0.0, 2.0});
    ASSERT_TRUE(uv.has_value());
    EXPECT_EQ(*uv, Vector2d(530.3, 370.8)) << lens.name;
  }
}

TEST(CameraModelUnproject, InvertsProjectToTheRayOfThePoint) {
  std::vector<Lens> lenses = RadTanLenses(kXgaSkewed);
  lenses.push_back(FisheyeLens(kFisheyeSkewed));
  lenses.push_back(WideFisheyeLens());
  unsigned seed = 500;
  for (const Lens& lens : lenses) {
    SCOPED_TRACE(lens.name);
    const CameraModel camera = lens.Camera();
    std::mt19937 rng(seed++);
    // Points in front of the camera over the whole image: from OpenCV's inverse for the
    // models OpenCV covers, from directions up to 89 degrees off-axis for the wide fisheye.
    std::vector<Vector3d> points;
    if (lens.name == "wide fisheye") {
      std::uniform_real_distribution<double> theta(0.0, 89.0 * std::numbers::pi / 180.0),
          phi(-std::numbers::pi, std::numbers::pi), depth(0.05, 50.0);
      for (int i = 0; i < kSamples; ++i) {
        const double t = theta(rng), p = phi(rng), d = depth(rng);
        points.emplace_back(d * std::sin(t) * std::cos(p), d * std::sin(t) * std::sin(p),
                            d * std::cos(t));
      }
    } else {
      points = PointsOnPixels(lens, PixelsCoveringImage(lens.K, kSamples, seed), seed);
    }
    double worst = 0.0;
    for (const Vector3d& p : points) {
      const std::optional<Vector2d> uv = camera.Project(p);
      ASSERT_TRUE(uv.has_value());
      const std::optional<Vector3d> ray = camera.Unproject(*uv);
      ASSERT_TRUE(ray.has_value()) << "pixel " << uv->transpose();
      EXPECT_NEAR(ray->norm(), 1.0, 1e-15);
      const double angle = AngleBetween(*ray, p);
      worst = std::max(worst, angle);
      EXPECT_LE(angle, kRayAngleTolerance) << "point " << p.transpose();
    }
    std::printf("[ measured ] %s Unproject(Project(p)): worst %.3g rad\n", lens.name.c_str(),
                worst);
  }
}

TEST(CameraModelUnproject, WideFisheyeRaysBeyond90DegreesRoundTrip) {
  const CameraModel camera = WideFisheyeLens().Camera();
  std::mt19937 rng(600);
  // Up to 135 degrees off-axis: Z < 0 for most of them.
  std::uniform_real_distribution<double> theta(0.0, 135.0 * std::numbers::pi / 180.0),
      phi(-std::numbers::pi, std::numbers::pi), depth(0.05, 50.0);
  int behind = 0, inside = 0;
  double worst = 0.0;
  for (int i = 0; i < kSamples; ++i) {
    const double t = theta(rng), p = phi(rng), d = depth(rng);
    const Vector3d point(d * std::sin(t) * std::cos(p), d * std::sin(t) * std::sin(p),
                         d * std::cos(t));
    behind += point.z() < 0.0;
    const std::optional<Vector2d> uv = camera.Project(point);
    ASSERT_TRUE(uv.has_value()) << point.transpose();
    inside += camera.Contains(*uv);
    const std::optional<Vector3d> ray = camera.Unproject(*uv);
    ASSERT_TRUE(ray.has_value()) << "pixel " << uv->transpose();
    const double angle = AngleBetween(*ray, point);
    worst = std::max(worst, angle);
    EXPECT_LE(angle, kRayAngleTolerance) << "point " << point.transpose();
  }
  EXPECT_GT(behind, kSamples / 4);  // a third of the angles are beyond 90 degrees
  EXPECT_GT(inside, kSamples / 2);
  // The image corners are ~136 degrees off-axis: every pixel unprojects.
  for (const Vector2d& uv : PixelsCoveringImage(camera.intrinsics(), 0, 0)) {
    const std::optional<Vector3d> ray = camera.Unproject(uv);
    ASSERT_TRUE(ray.has_value()) << uv.transpose();
    EXPECT_LT(ray->z(), 0.0) << "corner " << uv.transpose() << " looks beyond 90 degrees";
    const std::optional<Vector2d> back = camera.Project(*ray);
    ASSERT_TRUE(back.has_value());
    EXPECT_LE((*back - uv).norm(), kRoundTripTolerancePx);
  }
  std::printf("[ measured ] wide fisheye beyond 90 deg: worst %.3g rad\n", worst);
}

// distort(undistort(p)) = p over the whole image, corners included, and every pixel converges.
TEST(CameraModelUndistortPixel, DistortOfUndistortReturnsThePixel) {
  std::vector<Lens> lenses = RadTanLenses(kXgaSkewed);
  lenses.push_back(FisheyeLens(kFisheyeSkewed));
  unsigned seed = 700;
  for (const Lens& lens : lenses) {
    SCOPED_TRACE(lens.name);
    const CameraModel camera = lens.Camera();
    double worst = 0.0;
    for (const Vector2d& uv : PixelsCoveringImage(lens.K, kSamples, seed++)) {
      const UndistortResult result = camera.UndistortPixel(uv);
      ASSERT_TRUE(result.converged)
          << "pixel " << uv.transpose() << " residual " << result.residual;
      EXPECT_LE(result.residual, 1e-14);
      const double error = (camera.DistortPixel(result.point) - uv).norm();
      worst = std::max(worst, error);
      EXPECT_LE(error, kRoundTripTolerancePx) << "pixel " << uv.transpose();
    }
    std::printf("[ measured ] %s DistortPixel(UndistortPixel(p)): worst %.3g px\n",
                lens.name.c_str(), worst);
  }
}

TEST(CameraModelUndistortPixel, MatchesCvUndistortPoints) {
  // cv::undistortPoints reads no skew from its camera matrix: these lenses have none.
  unsigned seed = 800;
  for (const Lens& lens : RadTanLenses(kXga)) {
    SCOPED_TRACE(lens.name);
    const CameraModel camera = lens.Camera();
    const std::vector<Vector2d> pixels = PixelsCoveringImage(lens.K, kSamples, seed++);
    std::vector<cv::Point2d> reference;
    cv::undistortPoints(
        ToCv(pixels), reference, CvMatrix(lens.K), lens.coefficients, cv::noArray(),
        CvMatrix(lens.K),
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 1000, 1e-15));
    double worst = 0.0;
    for (size_t i = 0; i < pixels.size(); ++i) {
      const UndistortResult result = camera.UndistortPixel(pixels[i]);
      ASSERT_TRUE(result.converged);
      const double error = (result.point - Vector2d(reference[i].x, reference[i].y)).norm();
      worst = std::max(worst, error);
      EXPECT_LE(error, kUndistortVsOpenCvPx) << "pixel " << pixels[i].transpose();
    }
    std::printf("[ measured ] %s UndistortPixel vs cv::undistortPoints: worst %.3g px\n",
                lens.name.c_str(), worst);
  }
}

TEST(CameraModelUndistortPixel, MatchesCvFisheyeUndistortPoints) {
  // cv::fisheye::undistortPoints reads no skew (alpha) from K: this lens has none.
  const Lens lens = FisheyeLens(kFisheyeK);
  const CameraModel camera = lens.Camera();
  const std::vector<Vector2d> pixels = PixelsCoveringImage(lens.K, kSamples, 900);
  std::vector<cv::Point2d> reference;
  cv::fisheye::undistortPoints(
      ToCv(pixels), reference, CvMatrix(lens.K), lens.coefficients, cv::noArray(), CvMatrix(lens.K),
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-14));
  double worst = 0.0;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const UndistortResult result = camera.UndistortPixel(pixels[i]);
    ASSERT_TRUE(result.converged);
    const double error = (result.point - Vector2d(reference[i].x, reference[i].y)).norm();
    worst = std::max(worst, error);
    EXPECT_LE(error, kUndistortVsOpenCvPx) << "pixel " << pixels[i].transpose();
  }
  std::printf(
      "[ measured ] fisheye UndistortPixel vs cv::fisheye::undistortPoints: worst %.3g px\n",
      worst);
}

// With k1 = -0.5 the radial profile r (1 - r^2 / 2) peaks at r = sqrt(2/3), r_d = 0.544, and
// folds back: pixels farther out have no preimage on the lens's branch (only one on the far,
// mirrored branch), and Undistort must say so rather than answer with that point.
TEST(CameraModelUndistortPixel, FoldedLensReportsNonConvergence) {
  const Intrinsics K(1024, 768, 500.0, 500.0, 511.5, 383.5);
  const CameraModel camera(K, Distortion::RadialTangential(std::vector{-0.5, 0.0, 0.0, 0.0}));
  const double fold_rd = std::sqrt(2.0 / 3.0) * (1.0 - 1.0 / 3.0);
  // Inside the fold: converges to the branch through the centre.
  const UndistortResult inside = camera.UndistortPixel({511.5 + 0.99 * fold_rd * 500.0, 383.5});
  EXPECT_TRUE(inside.converged);
  EXPECT_LT((inside.point.x() - 511.5) / 500.0, std::sqrt(2.0 / 3.0));
  // Beyond the fold (normalized radius 0.6, at pixel 811.5 in this 1024 wide image).
  const Vector2d beyond(511.5 + 0.6 * 500.0, 383.5);
  ASSERT_TRUE(camera.Contains(beyond));
  const UndistortResult result = camera.UndistortPixel(beyond);
  EXPECT_FALSE(result.converged) << "answered " << result.point.transpose();
  EXPECT_FALSE(camera.Unproject(beyond).has_value());
  // A root does exist, mirrored through the centre: x^3 / 2 - x - 0.6 = 0 at x = 1.65127...
  const double x_far = -1.6512755483029526;
  EXPECT_NEAR(camera.distortion().Distort({x_far, 0.0}).x(), 0.6, 1e-12);
}

TEST(CameraModelContains, UsesThePixelEdges) {
  const CameraModel camera(Intrinsics(640, 480, 500, 500, 320, 240));
  EXPECT_TRUE(camera.Contains({-0.5, -0.5}));
  EXPECT_TRUE(camera.Contains({639.49, 479.49}));
  EXPECT_FALSE(camera.Contains({639.5, 100}));
  EXPECT_FALSE(camera.Contains({100, 479.5}));
  EXPECT_FALSE(camera.Contains({-0.51, 100}));
  EXPECT_FALSE(camera.Contains({100, -0.51}));
  EXPECT_FALSE(camera.Contains({std::nan(""), 100}));
}

// The camera model's one JSON form (frames.jsonl, the GUI's scene document) carries it
// whole: K row by row as OpenCV's camera matrix, the distortion's model and coefficients; it
// reads back to the same model, and a bad one names the field and what was expected.
TEST(CameraModelJson, RoundTripsAndNamesWhatIsWrong) {
  const CameraModel model(
      Intrinsics(640, 480, 500.5, 501.25, 319.5, 239.25, 0.5),
      Distortion::RadialTangential(std::vector<double>{-0.2, 0.1, 1e-3, -2e-3, 0.01}));
  const nlohmann::json j = ToJson(model);
  EXPECT_EQ(j["K"], nlohmann::json::parse("[[500.5, 0.5, 319.5], [0, 501.25, 239.25], [0, 0, 1]]"));
  EXPECT_EQ(j["distortion"]["model"], "radtan");
  const CameraModel back = JsonCodec<CameraModel>::Decode(j, {"camera", ""});
  EXPECT_TRUE(back == model);
  nlohmann::json bad = j;
  bad["distortion"]["model"] = "pinhole";
  try {
    JsonCodec<CameraModel>::Decode(bad, {"scene", "camera"});
    ADD_FAILURE() << "accepted a model named pinhole";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("scene: field 'camera': expected {width, height, K"),
              std::string::npos)
        << e.what();
  }
  bad = j;
  bad["K"][1][1] = -1.0;  // a negative focal length: the intrinsics refuse it
  EXPECT_THROW(JsonCodec<CameraModel>::Decode(bad, {"camera", ""}), Error);
}

}  // namespace
}  // namespace saccade::geometry
