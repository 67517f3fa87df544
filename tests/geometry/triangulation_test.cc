#include "saccade/geometry/triangulation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <random>

#include "saccade/geometry/pose.h"

namespace saccade::geometry {
namespace {

// Exact observations: only rounding remains, a few ulps of metres-sized numbers.
constexpr double kExactTolerance = 1e-9;

// A random camera looking at the origin region from 1-5 m away.
Pose RandomCamera(std::mt19937& rng) {
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), distance(1.0, 5.0);
  const Eigen::Matrix3d R = RotationFromRpy(angle(rng), angle(rng), angle(rng));
  return MakePose(R, R * Eigen::Vector3d(0, 0, -distance(rng)));  // X_CW: world origin ahead
}

Eigen::Matrix<double, 3, 4> View(const Pose& X_CW) { return X_CW.matrix().topRows<3>(); }

TEST(TriangulateMidpoint, ExactRaysRecoverThePoint) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coordinate(-0.5, 0.5);
  double worst = 0.0;
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d p(coordinate(rng), coordinate(rng), coordinate(rng));
    const Eigen::Vector3d oa(-0.1, 0.02 * i / 1000.0, -2.0), ob(0.1, 0.0, -2.1);
    const TriangulationResult r =
        TriangulateMidpoint({oa, (p - oa).normalized()}, {ob, (p - ob).normalized()});
    ASSERT_TRUE(r.ok());
    worst = std::max(worst, (r.point - p).norm());
    EXPECT_LT(r.gap, kExactTolerance);
  }
  EXPECT_LT(worst, kExactTolerance);
}

TEST(TriangulateMidpoint, SkewRaysGiveTheMidpointAndTheGap) {
  // Ray a along x at z = 0, ray b along y at z = 1: closest points (0,0,0) and (0,0,1).
  const TriangulationResult r =
      TriangulateMidpoint({{-1, 0, 0}, {1, 0, 0}}, {{0, -2, 1}, {0, 1, 0}});
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR((r.point - Eigen::Vector3d(0, 0, 0.5)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(r.gap, 1.0, 1e-15);
  EXPECT_NEAR(r.ray_param_a, 1.0, 1e-15);
  EXPECT_NEAR(r.ray_param_b, 2.0, 1e-15);
}

TEST(TriangulateMidpoint, ParallelRaysAreReportedNotDividedByZero) {
  const TriangulationResult r =
      TriangulateMidpoint({{0, 0, 0}, {0, 0, 1}}, {{0.1, 0, 0}, {0, 0, 1}});
  EXPECT_TRUE(r.parallel);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(std::isfinite(r.point.norm()));
  EXPECT_NEAR(r.gap, 0.1, 1e-15);  // distance between the parallel lines
  const TriangulationResult nearly =
      TriangulateMidpoint({{0, 0, 0}, {0, 0, 1}}, {{0.1, 0, 0}, Eigen::Vector3d(1e-12, 0, 1)});
  EXPECT_TRUE(nearly.parallel);
}

TEST(TriangulateMidpoint, PointBehindTheCamerasIsFlagged) {
  // Diverging rays: their closest points lie behind both origins.
  const TriangulationResult r =
      TriangulateMidpoint({{-0.1, 0, 0}, Eigen::Vector3d(-0.1, 0, 1).normalized()},
                          {{0.1, 0, 0}, Eigen::Vector3d(0.1, 0, 1).normalized()});
  EXPECT_FALSE(r.parallel);
  EXPECT_TRUE(r.behind);
  EXPECT_FALSE(r.ok());
}

TEST(TriangulateDlt, MatchesOpenCvTriangulatePoints) {
  // cv::triangulatePoints is OpenCV's DLT (Hartley & Zisserman 12.2), the reference here.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coordinate(-0.5, 0.5), noise(-1e-3, 1e-3);
  double worst_exact = 0.0, worst_vs_opencv = 0.0;
  for (int i = 0; i < 500; ++i) {
    const Pose Xa = RandomCamera(rng), Xb = RandomCamera(rng);
    const Eigen::Vector3d p(coordinate(rng), coordinate(rng), coordinate(rng));
    const Eigen::Vector3d pa = Xa * p, pb = Xb * p;
    if (pa.z() < 0.2 || pb.z() < 0.2) continue;
    const Eigen::Vector2d xa = pa.hnormalized(), xb = pb.hnormalized();
    worst_exact =
        std::max(worst_exact, (TriangulateDlt(View(Xa), xa, View(Xb), xb).point - p).norm());

    // Noisy observations: both solve the same least squares problem, so they must agree.
    const Eigen::Vector2d na = xa + Eigen::Vector2d(noise(rng), noise(rng));
    const Eigen::Vector2d nb = xb + Eigen::Vector2d(noise(rng), noise(rng));
    const TriangulationResult ours = TriangulateDlt(View(Xa), na, View(Xb), nb);
    cv::Mat Pa, Pb, X;
    cv::eigen2cv(Eigen::Matrix<double, 3, 4>(View(Xa)), Pa);
    cv::eigen2cv(Eigen::Matrix<double, 3, 4>(View(Xb)), Pb);
    cv::triangulatePoints(Pa, Pb, cv::Mat(cv::Vec2d(na.x(), na.y())),
                          cv::Mat(cv::Vec2d(nb.x(), nb.y())), X);
    const Eigen::Vector3d reference(X.at<double>(0) / X.at<double>(3),
                                    X.at<double>(1) / X.at<double>(3),
                                    X.at<double>(2) / X.at<double>(3));
    worst_vs_opencv = std::max(worst_vs_opencv, (ours.point - reference).norm());
  }
  EXPECT_LT(worst_exact, kExactTolerance);
  // Both are SVDs of the same 4x4 system; they differ by rounding only.
  EXPECT_LT(worst_vs_opencv, 1e-9);
}

TEST(TriangulateMidpoint, DepthErrorUnderPixelNoiseMatchesStereoGeometry) {
  // Rectified stereo, baseline b, focal f (px), depth Z, independent Gaussian noise of sigma px
  // on both horizontal pixel coordinates: disparity noise sigma*sqrt(2), and to first order
  // sigma_Z = Z^2 / (f b) * sigma * sqrt(2).
  const double f = 1290.0, b = 0.2, Z = 3.0, sigma = 0.25;
  std::mt19937 rng(3);
  std::normal_distribution<double> pixel_noise(0.0, sigma);
  const int kSamples = 20000;
  double sum = 0.0, sum_sq = 0.0;
  const Eigen::Vector3d p(0.05, -0.02, Z);
  const Eigen::Vector3d ol(0, 0, 0), orr(b, 0, 0);
  for (int i = 0; i < kSamples; ++i) {
    const Eigen::Vector2d ul = p.hnormalized() + Eigen::Vector2d(pixel_noise(rng) / f, 0);
    const Eigen::Vector2d ur = (p - orr).hnormalized() + Eigen::Vector2d(pixel_noise(rng) / f, 0);
    const TriangulationResult r = TriangulateMidpoint({ol, ul.homogeneous().normalized()},
                                                      {orr, ur.homogeneous().normalized()});
    ASSERT_TRUE(r.ok());
    const double dz = r.point.z() - Z;
    sum += dz;
    sum_sq += dz * dz;
  }
  const double mean = sum / kSamples;
  const double measured = std::sqrt(sum_sq / kSamples - mean * mean);
  const double predicted = Z * Z / (f * b) * sigma * std::sqrt(2.0);
  // 20000 samples: the standard deviation estimate is good to ~0.5 %; the first-order model
  // neglects terms of order (sigma_d / d)^2 ~ 1e-4. 3 % covers both with margin.
  EXPECT_NEAR(measured / predicted, 1.0, 0.03)
      << "measured " << measured << " m, predicted " << predicted << " m";
}

}  // namespace
}  // namespace saccade::geometry
