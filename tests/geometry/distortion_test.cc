// Distortion against OpenCV 4.6: cv::projectPoints / cv::fisheye::projectPoints with an identity
// camera matrix give the distorted normalized coordinates and, through their Jacobians with
// respect to the translation, the analytic Jacobian of the model.

#include "saccade/geometry/distortion.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <opencv2/calib3d.hpp>
#include <random>
#include <string>
#include <vector>

#include "saccade/core/error.h"

namespace saccade::geometry {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::StartsWith;

// Normalized coordinates are O(1): the same polynomial evaluated in OpenCV's order and ours
// differs by a few ulps; 1e-13 leaves margin and still catches any wrong term.
constexpr double kNormalizedTolerance = 1e-13;
// OpenCV's Jacobian uses other (equivalent) formulas; relative rounding ~1e-14.
constexpr double kJacobianTolerance = 1e-10;
// Undistort stops at a residual of 1e-14 (default tolerance); OpenCV's fixed-point iteration
// (radtan) and 1D Newton (fisheye) stop within a few 1e-15: both answers agree to ~1e-13.
constexpr double kUndistortVsOpenCv = 1e-11;
// atan2(rho, Z) versus OpenCV's atan(rho / Z) for Z > 0: one rounding of rho / Z apart.
constexpr double kAtan2VersusAtan = 1e-15;
constexpr int kSamples = 3000;

const std::vector<double> kRadTan4 = {-0.30, 0.09, 0.0012, -0.0009};
const std::vector<double> kRadTan5 = {-0.42, 0.25, -0.0007, 0.0015, -0.06};
const std::vector<double> kRadTan8 = {2.0, 0.5, 0.0005, -0.0011, 0.01, 2.4, 1.1, 0.05};
const std::vector<double> kFisheye = {0.05, -0.02, 0.005, -0.0005};

std::string ThrownMessage(const std::function<void()>& f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "<no InvalidArgument thrown>";
}

// Random undistorted normalized points in a disc of the given radius (corners of a wide image
// reach ~1.1).
std::vector<Vector2d> RandomNormalized(double radius, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-radius, radius);
  std::vector<Vector2d> points;
  while (static_cast<int>(points.size()) < n) {
    const Vector2d p(uniform(rng), uniform(rng));
    if (p.norm() <= radius) points.push_back(p);
  }
  return points;
}

struct CvResult {
  std::vector<Vector2d> xd;
  cv::Mat jacobian;
};

// cv::projectPoints of (x, y, 1) with an identity camera matrix.
CvResult CvRadTan(const std::vector<Vector2d>& xy, const std::vector<double>& coefficients) {
  std::vector<cv::Point3d> object;
  for (const Vector2d& p : xy) object.emplace_back(p.x(), p.y(), 1.0);
  std::vector<cv::Point2d> image;
  CvResult result;
  cv::projectPoints(object, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), cv::Matx33d::eye(),
                    coefficients, image, result.jacobian);
  for (const cv::Point2d& p : image) result.xd.emplace_back(p.x, p.y);
  return result;
}

CvResult CvFisheye(const std::vector<Vector3d>& points, const std::vector<double>& coefficients) {
  std::vector<cv::Point3d> object;
  for (const Vector3d& p : points) object.emplace_back(p.x(), p.y(), p.z());
  std::vector<cv::Point2d> image;
  CvResult result;
  cv::fisheye::projectPoints(object, image, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0),
                             cv::Matx33d::eye(), coefficients, 0.0, result.jacobian);
  for (const cv::Point2d& p : image) result.xd.emplace_back(p.x, p.y);
  return result;
}

// --- construction and validation -------------------------------------------------------------

TEST(DistortionCoefficients, RadTanAcceptsOpenCvCountsAndStoresEight) {
  for (const std::vector<double>& c : {kRadTan4, kRadTan5, kRadTan8}) {
    const Distortion d = Distortion::RadialTangential(c);
    EXPECT_EQ(d.model(), DistortionModel::kRadialTangential);
    ASSERT_EQ(d.coefficients().size(), 8u);
    for (size_t i = 0; i < 8; ++i) EXPECT_EQ(d.coefficients()[i], i < c.size() ? c[i] : 0.0);
  }
  std::vector<double> twelve = kRadTan8, fourteen = kRadTan8;
  twelve.resize(12, 0.0);
  fourteen.resize(14, 0.0);
  EXPECT_EQ(Distortion::RadialTangential(twelve), Distortion::RadialTangential(kRadTan8));
  EXPECT_EQ(Distortion::RadialTangential(fourteen), Distortion::RadialTangential(kRadTan8));
}

TEST(DistortionCoefficients, RadTanRejectsOtherCountsNamingTheCount) {
  for (size_t n : {0u, 1u, 3u, 6u, 7u, 9u, 13u, 15u}) {
    const std::vector<double> c(n, 0.01);
    EXPECT_THAT(ThrownMessage([&] { Distortion::RadialTangential(c); }),
                AllOf(StartsWith("Distortion::RadialTangential:"),
                      HasSubstr("expected 4, 5, 8, 12 or 14 coefficients"),
                      HasSubstr("got " + std::to_string(n))));
  }
}

TEST(DistortionCoefficients, RadTanRejectsNonFiniteNamingTheCoefficient) {
  const char* names[] = {"k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6"};
  for (int i = 0; i < 8; ++i) {
    for (double bad :
         {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity()}) {
      std::vector<double> c = kRadTan8;
      c[i] = bad;
      EXPECT_THAT(
          ThrownMessage([&] { Distortion::RadialTangential(c); }),
          AllOf(StartsWith("Distortion::RadialTangential:"),
                HasSubstr(std::string("coefficient ") + names[i]), HasSubstr("must be finite"),
                HasSubstr(std::isnan(bad) ? "got nan" : (bad > 0 ? "got inf" : "got -inf"))));
    }
  }
}

TEST(DistortionCoefficients, RadTanRejectsThinPrismAndTiltTerms) {
  std::vector<double> c = kRadTan8;
  c.resize(12, 0.0);
  c[9] = 0.25;  // s2
  EXPECT_THAT(ThrownMessage([&] { Distortion::RadialTangential(c); }),
              AllOf(HasSubstr("s2"), HasSubstr("got 0.25"), HasSubstr("not supported")));
  c.resize(14, 0.0);
  c[9] = 0.0;
  c[13] = -0.5;  // tau_y
  EXPECT_THAT(ThrownMessage([&] { Distortion::RadialTangential(c); }),
              AllOf(HasSubstr("tau_y"), HasSubstr("got -0.5")));
}

TEST(DistortionCoefficients, FisheyeNeedsExactlyFourFiniteCoefficients) {
  for (size_t n : {0u, 3u, 5u, 8u}) {
    const std::vector<double> c(n, 0.01);
    EXPECT_THAT(ThrownMessage([&] { Distortion::Fisheye(c); }),
                AllOf(StartsWith("Distortion::Fisheye:"), HasSubstr("exactly 4"),
                      HasSubstr("got " + std::to_string(n))));
  }
  std::vector<double> c = kFisheye;
  c[2] = std::numeric_limits<double>::infinity();
  EXPECT_THAT(ThrownMessage([&] { Distortion::Fisheye(c); }),
              AllOf(StartsWith("Distortion::Fisheye:"), HasSubstr("k3"), HasSubstr("got inf")));
  c[2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THAT(ThrownMessage([&] { Distortion::Fisheye(c); }),
              AllOf(HasSubstr("k3"), HasSubstr("got nan")));
  EXPECT_EQ(Distortion::Fisheye(kFisheye).coefficients(), kFisheye);
}

TEST(DistortionCoefficients, FromCoefficientsDispatchesAndNoneTakesOnlyZeros) {
  EXPECT_EQ(Distortion::FromCoefficients(DistortionModel::kRadialTangential, kRadTan5),
            Distortion::RadialTangential(kRadTan5));
  EXPECT_EQ(Distortion::FromCoefficients(DistortionModel::kFisheye, kFisheye),
            Distortion::Fisheye(kFisheye));
  EXPECT_EQ(Distortion::FromCoefficients(DistortionModel::kNone, {}), Distortion());
  EXPECT_EQ(Distortion::FromCoefficients(DistortionModel::kNone, std::vector<double>(5, 0.0)),
            Distortion());
  EXPECT_THAT(ThrownMessage([] {
                Distortion::FromCoefficients(DistortionModel::kNone, std::vector{0.0, 0.125});
              }),
              AllOf(StartsWith("Distortion::FromCoefficients:"), HasSubstr("none"),
                    HasSubstr("got 0.125 at index 1")));
  EXPECT_THAT(ThrownMessage([] {
                Distortion::FromCoefficients(DistortionModel::kFisheye, std::vector{0.1});
              }),
              HasSubstr("Distortion::Fisheye: expected exactly 4"));
}

TEST(DistortionModel, NamesAndIdentity) {
  EXPECT_EQ(ToString(DistortionModel::kNone), "none");
  EXPECT_EQ(ToString(DistortionModel::kRadialTangential), "radtan");
  EXPECT_EQ(ToString(DistortionModel::kFisheye), "fisheye");
  EXPECT_TRUE(Distortion().IsIdentity());
  EXPECT_TRUE(Distortion::RadialTangential(std::vector<double>(5, 0.0)).IsIdentity());
  EXPECT_FALSE(Distortion::RadialTangential(kRadTan4).IsIdentity());
  EXPECT_FALSE(Distortion::Fisheye(std::vector<double>(4, 0.0)).IsIdentity())
      << "a zero fisheye is the equidistant projection";
  const Distortion zero_fisheye = Distortion::Fisheye(std::vector<double>(4, 0.0));
  EXPECT_NEAR(zero_fisheye.Distort({1.0, 0.0}).x(), std::numbers::pi / 4, 1e-15);
}

// --- the forward model ---------------------------------------------------------------------------

TEST(DistortionDistort, RadTanMatchesCvProjectPointsAndItsJacobian) {
  unsigned seed = 10;
  for (const std::vector<double>& c : {kRadTan4, kRadTan5, kRadTan8}) {
    SCOPED_TRACE(c.size());
    const Distortion d = Distortion::RadialTangential(c);
    const std::vector<Vector2d> xy = RandomNormalized(1.2, kSamples, seed++);
    const CvResult cv = CvRadTan(xy, c);
    // jacobian columns: rvec (0-2), tvec (3-5), f, c, distortion. With Z = 1 and K = I,
    // d(xd)/d(tx, ty) is the Jacobian of the model with respect to (x, y).
    double worst = 0.0, worst_jacobian = 0.0;
    for (size_t i = 0; i < xy.size(); ++i) {
      const double error = (d.Distort(xy[i]) - cv.xd[i]).norm();
      worst = std::max(worst, error);
      EXPECT_LE(error, kNormalizedTolerance) << xy[i].transpose();
      Eigen::Matrix2d reference;
      reference << cv.jacobian.at<double>(2 * i, 3), cv.jacobian.at<double>(2 * i, 4),
          cv.jacobian.at<double>(2 * i + 1, 3), cv.jacobian.at<double>(2 * i + 1, 4);
      const double jacobian_error =
          (d.DistortJacobian(xy[i]) - reference).norm() / std::max(1.0, reference.norm());
      worst_jacobian = std::max(worst_jacobian, jacobian_error);
      EXPECT_LE(jacobian_error, kJacobianTolerance) << xy[i].transpose();
    }
    std::printf("[ measured ] radtan%zu Distort vs cv::projectPoints: %.3g, Jacobian %.3g\n",
                c.size(), worst, worst_jacobian);
  }
}

TEST(DistortionDistort, FisheyeMatchesCvFisheyeProjectPointsAndItsJacobian) {
  const Distortion d = Distortion::Fisheye(kFisheye);
  std::vector<Vector3d> points;
  for (const Vector2d& p : RandomNormalized(3.0, kSamples, 20))
    points.emplace_back(p.x(), p.y(), 1);
  const CvResult cv = CvFisheye(points, kFisheye);
  // fisheye jacobian columns: f (0-1), c (2-3), k (4-7), om (8-10), T (11-13), alpha (14).
  double worst = 0.0, worst_jacobian = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    const Vector2d xy = points[i].head<2>();
    const double error = (d.Distort(xy) - cv.xd[i]).norm();
    worst = std::max(worst, error);
    EXPECT_LE(error, kNormalizedTolerance) << xy.transpose();
    Eigen::Matrix2d reference;
    reference << cv.jacobian.at<double>(2 * i, 11), cv.jacobian.at<double>(2 * i, 12),
        cv.jacobian.at<double>(2 * i + 1, 11), cv.jacobian.at<double>(2 * i + 1, 12);
    const double jacobian_error =
        (d.DistortJacobian(xy) - reference).norm() / std::max(1.0, reference.norm());
    worst_jacobian = std::max(worst_jacobian, jacobian_error);
    EXPECT_LE(jacobian_error, kJacobianTolerance) << xy.transpose();
  }
  std::printf("[ measured ] fisheye Distort vs cv::fisheye::projectPoints: %.3g, Jacobian %.3g\n",
              worst, worst_jacobian);
}

TEST(DistortionDistortRay, FisheyeAtan2AgreesWithOpenCvAtanInFront) {
  const Distortion d = Distortion::Fisheye(kFisheye);
  std::mt19937 rng(30);
  std::uniform_real_distribution<double> lateral(-5.0, 5.0), depth(1e-3, 10.0);
  std::vector<Vector3d> points;
  for (int i = 0; i < kSamples; ++i) points.emplace_back(lateral(rng), lateral(rng), depth(rng));
  const CvResult cv = CvFisheye(points, kFisheye);
  double worst = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    Vector2d xd;
    ASSERT_TRUE(d.DistortRay(points[i], &xd));
    const double error = (xd - cv.xd[i]).norm() / std::max(1.0, xd.norm());
    worst = std::max(worst, error);
    EXPECT_LE(error, kAtan2VersusAtan) << points[i].transpose();
  }
  std::printf("[ measured ] fisheye DistortRay (atan2) vs OpenCV (atan): %.3g relative\n", worst);
}

TEST(DistortionDistortRay, FisheyeBeyond90DegreesFollowsKannalaBrandtInPolarForm) {
  const Distortion d = Distortion::Fisheye(kFisheye);
  std::mt19937 rng(40);
  std::uniform_real_distribution<double> theta(0.5 * std::numbers::pi, 0.95 * std::numbers::pi),
      phi(-std::numbers::pi, std::numbers::pi), length(1e-3, 100.0);
  for (int i = 0; i < kSamples; ++i) {
    const double t = theta(rng), p = phi(rng), l = length(rng);
    const Vector3d ray(l * std::sin(t) * std::cos(p), l * std::sin(t) * std::sin(p),
                       l * std::cos(t));
    Vector2d xd;
    ASSERT_TRUE(d.DistortRay(ray, &xd));
    const double t2 = t * t;
    const double theta_d =
        t * (1 + t2 * (kFisheye[0] + t2 * (kFisheye[1] + t2 * (kFisheye[2] + t2 * kFisheye[3]))));
    EXPECT_NEAR(xd.x(), theta_d * std::cos(p), 1e-12);
    EXPECT_NEAR(xd.y(), theta_d * std::sin(p), 1e-12);
  }
}

TEST(DistortionDistortRay, FisheyeIsContinuousThroughTheImagePlane) {
  const Distortion d = Distortion::Fisheye(kFisheye);
  Vector2d in_front, behind;
  ASSERT_TRUE(d.DistortRay({0.6, -0.8, 1e-12}, &in_front));
  ASSERT_TRUE(d.DistortRay({0.6, -0.8, -1e-12}, &behind));
  EXPECT_LE((in_front - behind).norm(), 1e-11);
  Vector2d at_90;
  ASSERT_TRUE(d.DistortRay({0.6, -0.8, 0.0}, &at_90));
  EXPECT_LE((in_front - at_90).norm(), 1e-11);
}

TEST(DistortionDistortRay, RaysThatCannotBeImagedReturnFalse) {
  Vector2d xd;
  for (const Distortion& d : {Distortion(), Distortion::RadialTangential(kRadTan5)}) {
    EXPECT_FALSE(d.DistortRay({0.1, 0.1, 0.0}, &xd));
    EXPECT_FALSE(d.DistortRay({0.1, 0.1, -1.0}, &xd));
    EXPECT_FALSE(d.DistortRay({0.0, 0.0, 0.0}, &xd));
    EXPECT_TRUE(d.DistortRay({0.1, 0.1, 1.0}, &xd));
  }
  const Distortion fisheye = Distortion::Fisheye(kFisheye);
  EXPECT_FALSE(fisheye.DistortRay({0.0, 0.0, 0.0}, &xd));
  EXPECT_FALSE(fisheye.DistortRay({0.0, 0.0, -2.0}, &xd)) << "straight backward has no direction";
  EXPECT_FALSE(fisheye.DistortRay({std::nan(""), 0.0, 1.0}, &xd));
}

TEST(DistortionDistortRay, FisheyeFollowsOpenCvNearTheAxis) {
  // cv::fisheye::projectPoints uses distortion factor 1 below r = 1e-8.
  const Distortion d = Distortion::Fisheye(std::vector{0.5, 0.2, 0.1, 0.05});
  Vector2d xd;
  ASSERT_TRUE(d.DistortRay({3e-9, -4e-9, 1.0}, &xd));
  EXPECT_EQ(xd, Vector2d(3e-9, -4e-9));
  ASSERT_TRUE(d.DistortRay({0.0, 0.0, 5.0}, &xd));
  EXPECT_EQ(xd, Vector2d(0.0, 0.0));
  const CvResult cv = CvFisheye({{3e-9, -4e-9, 1.0}, {3e-8, -4e-8, 1.0}}, d.coefficients());
  EXPECT_EQ(d.Distort({3e-9, -4e-9}), cv.xd[0]);
  EXPECT_NEAR((d.Distort({3e-8, -4e-8}) - cv.xd[1]).norm(), 0.0, 1e-22);
}

// --- the inverse ---------------------------------------------------------------------------------

TEST(DistortionUndistort, RadTanInvertsDistortAndMatchesCvUndistortPoints) {
  unsigned seed = 50;
  for (const std::vector<double>& c : {kRadTan4, kRadTan5, kRadTan8}) {
    SCOPED_TRACE(c.size());
    const Distortion d = Distortion::RadialTangential(c);
    // Distorted points up to the corners of a wide image (|xd| ~ 0.85).
    const std::vector<Vector2d> xd = RandomNormalized(0.85, kSamples, seed++);
    std::vector<cv::Point2d> src, reference;
    for (const Vector2d& p : xd) src.emplace_back(p.x(), p.y());
    cv::undistortPoints(
        src, reference, cv::Matx33d::eye(), c, cv::noArray(), cv::noArray(),
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 1000, 1e-15));
    double worst = 0.0;
    for (size_t i = 0; i < xd.size(); ++i) {
      const UndistortResult result = d.Undistort(xd[i]);
      ASSERT_TRUE(result.converged) << xd[i].transpose();
      EXPECT_LE(result.residual, 1e-14);
      EXPECT_LE((d.Distort(result.point) - xd[i]).norm(), 1e-14);
      EXPECT_LE(result.iterations, 20);
      const double error = (result.point - Vector2d(reference[i].x, reference[i].y)).norm();
      worst = std::max(worst, error);
      EXPECT_LE(error, kUndistortVsOpenCv) << xd[i].transpose();
    }
    std::printf("[ measured ] radtan%zu Undistort vs cv::undistortPoints: %.3g normalized\n",
                c.size(), worst);
  }
}

TEST(DistortionUndistort, FisheyeInvertsDistortAndMatchesCvFisheyeUndistortPoints) {
  const Distortion d = Distortion::Fisheye(kFisheye);
  // theta_d up to 1.45 rad, theta up to ~80 degrees (OpenCV clips theta_d at pi / 2).
  const std::vector<Vector2d> xd = RandomNormalized(1.45, kSamples, 60);
  std::vector<cv::Point2d> src, reference;
  for (const Vector2d& p : xd) src.emplace_back(p.x(), p.y());
  cv::fisheye::undistortPoints(
      src, reference, cv::Matx33d::eye(), kFisheye, cv::noArray(), cv::noArray(),
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-14));
  double worst = 0.0;
  for (size_t i = 0; i < xd.size(); ++i) {
    const UndistortResult result = d.Undistort(xd[i]);
    ASSERT_TRUE(result.converged) << xd[i].transpose();
    EXPECT_LE((d.Distort(result.point) - xd[i]).norm(), 1e-14);
    const Vector2d cv_point(reference[i].x, reference[i].y);
    const double error = (result.point - cv_point).norm() / std::max(1.0, cv_point.norm());
    worst = std::max(worst, error);
    EXPECT_LE(error, kUndistortVsOpenCv) << xd[i].transpose();
  }
  std::printf("[ measured ] fisheye Undistort vs cv::fisheye::undistortPoints: %.3g relative\n",
              worst);
}

TEST(DistortionUndistort, NoneIsTheIdentity) {
  const UndistortResult result = Distortion().Undistort({0.3, -0.7});
  EXPECT_TRUE(result.converged);
  EXPECT_EQ(result.point, Vector2d(0.3, -0.7));
  EXPECT_EQ(result.residual, 0.0);
}

TEST(DistortionUndistort, NonFiniteInputDoesNotConvergeAndDoesNotThrow) {
  for (const Distortion& d :
       {Distortion(), Distortion::RadialTangential(kRadTan8), Distortion::Fisheye(kFisheye)}) {
    EXPECT_FALSE(d.Undistort({std::nan(""), 0.1}).converged);
    Vector3d ray;
    EXPECT_FALSE(d.UndistortToRay({0.1, std::numeric_limits<double>::infinity()}, &ray));
  }
}

// r_d = r (1 - r^2 / 2) rises to 0.5443 at r = sqrt(2/3), then falls through 0 at r = sqrt(2)
// and on to -inf: a distorted radius of 0.6 has a preimage only on that far, mirrored branch.
TEST(DistortionUndistort, RadTanBeyondTheFoldReportsNotConverged) {
  const Distortion d = Distortion::RadialTangential(std::vector{-0.5, 0.0, 0.0, 0.0});
  const double fold_r = std::sqrt(2.0 / 3.0);
  const double fold_rd = fold_r * (1.0 - 0.5 * fold_r * fold_r);
  // The root that exists on the mirrored branch: x^3 / 2 - x - 0.6 = 0.
  const Vector2d mirrored(-1.6512755483029526, 0.0);
  ASSERT_NEAR(d.Distort(mirrored).x(), 0.6, 1e-12);
  for (const Vector2d& xd : {Vector2d(0.6, 0.0), Vector2d(0.0, -0.6), Vector2d(0.5, 0.5)}) {
    const UndistortResult result = d.Undistort(xd);
    EXPECT_FALSE(result.converged) << xd.transpose() << " answered " << result.point.transpose();
    Vector3d ray;
    EXPECT_FALSE(d.UndistortToRay(xd, &ray));
  }
  // A hair beyond the fold, where Newton meets a near-singular Jacobian: no answer either.
  EXPECT_FALSE(d.Undistort({fold_rd * (1.0 + 1e-9), 0.0}).converged);
  // At the fold (as rounded), an answer may come, but only from the branch through the centre.
  const UndistortResult at_fold = d.Undistort({fold_rd, 0.0});
  if (at_fold.converged) {
    EXPECT_LE(at_fold.point.x(), fold_r);
  }
  // Just inside the fold: the branch through the centre.
  const UndistortResult inside = d.Undistort({0.98 * fold_rd, 0.0});
  EXPECT_TRUE(inside.converged);
  EXPECT_LT(inside.point.norm(), fold_r);
  EXPECT_GT(inside.point.x(), 0.0);
}

TEST(DistortionUndistort, FisheyeBeyondTheFoldReportsNotConverged) {
  // theta_d = theta - 0.3 theta^3 peaks at theta = 1.054, theta_d = 0.7027.
  const Distortion d = Distortion::Fisheye(std::vector{-0.3, 0.0, 0.0, 0.0});
  Vector3d ray;
  EXPECT_FALSE(d.Undistort({0.8, 0.0}).converged);
  EXPECT_FALSE(d.UndistortToRay({0.0, 0.8}, &ray));
  const UndistortResult inside = d.Undistort({0.69, 0.0});
  EXPECT_TRUE(inside.converged);
  EXPECT_LT(std::atan(inside.point.norm()), 1.0541);
}

// theta_d = theta - 0.3 theta^3 + 0.03 theta^5 rises to 0.756 at theta = 1.214, falls to 0.546 at
// theta = 2.128 and rises again: theta_d = 2.2 has a root at theta = 3.0 (< pi) on that third
// branch, where Newton started at theta = theta_d converges; it is not the lens's answer (that
// part of the image overlaps the centre's).
TEST(DistortionUndistort, FisheyeRootOnAFoldedBackBranchIsNotAnAnswer) {
  const Distortion d = Distortion::Fisheye(std::vector{-0.3, 0.03, 0.0, 0.0});
  const auto theta_d = [](double t) { return t - 0.3 * t * t * t + 0.03 * std::pow(t, 5); };
  ASSERT_LT(theta_d(2.95), 2.2);
  ASSERT_GT(theta_d(3.05), 2.2);
  Vector3d ray;
  for (const Vector2d& xd : {Vector2d(2.2, 0.0), Vector2d(0.0, -2.2), Vector2d(0.8, 0.0)}) {
    EXPECT_FALSE(d.UndistortToRay(xd, &ray)) << xd.transpose() << " answered " << ray.transpose();
    EXPECT_FALSE(d.Undistort(xd).converged);
  }
  // Inside the first branch the answer is the one through the centre.
  ASSERT_TRUE(d.UndistortToRay({0.7, 0.0}, &ray));
  EXPECT_LT(std::acos(ray.z()), 1.214);
  Vector2d xd;
  ASSERT_TRUE(d.DistortRay(ray, &xd));
  EXPECT_LE((xd - Vector2d(0.7, 0.0)).norm(), 1e-14);
}

TEST(DistortionUndistortToRay, FisheyeReturnsUnitRaysBeyond90Degrees) {
  const Distortion d = Distortion::Fisheye(std::vector{0.01, -0.005, 0.001, 0.0});
  std::mt19937 rng(70);
  std::uniform_real_distribution<double> theta(0.0, 0.75 * std::numbers::pi),
      phi(-std::numbers::pi, std::numbers::pi);
  double worst = 0.0;
  for (int i = 0; i < kSamples; ++i) {
    const double t = theta(rng), p = phi(rng);
    const Vector3d ray(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t));
    Vector2d xd;
    ASSERT_TRUE(d.DistortRay(ray, &xd));
    Vector3d back;
    ASSERT_TRUE(d.UndistortToRay(xd, &back)) << ray.transpose();
    EXPECT_NEAR(back.norm(), 1.0, 1e-15);
    worst = std::max(worst, std::atan2(back.cross(ray).norm(), back.dot(ray)));
  }
  EXPECT_LE(worst, 1e-13);
  // Normalized coordinates do not exist beyond 90 degrees: Undistort says so.
  Vector2d xd;
  ASSERT_TRUE(d.DistortRay({1.0, 0.0, -0.2}, &xd));
  EXPECT_FALSE(d.Undistort(xd).converged);
}

}  // namespace
}  // namespace saccade::geometry
