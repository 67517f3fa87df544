// Intrinsics: validation with messages, and the pinhole K against OpenCV.

#include "saccade/geometry/intrinsics.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

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
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::StartsWith;

// Pixels up to ~3000 from one multiply-add: a few 1e-13 px of rounding; 1e-9 px is the bar.
constexpr double kPixelTolerance = 1e-9;
// Normalized coordinates O(1) through one subtraction and division: a few ulps.
constexpr double kNormalizedTolerance = 1e-14;
// Field of view from atan of edge offsets versus the angle between OpenCV's back-projected
// edge rays: ~1e-16 rad each.
constexpr double kAngleTolerance = 1e-14;
constexpr int kSamples = 2000;

const double kNan = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

std::string ThrownMessage(const std::function<void()>& f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "<no InvalidArgument thrown>";
}

cv::Matx33d CvMatrix(const Intrinsics& K) {
  return cv::Matx33d(K.fx(), K.skew(), K.cx(), 0.0, K.fy(), K.cy(), 0.0, 0.0, 1.0);
}

TEST(Intrinsics, StoresItsFieldsAndMatrix) {
  const Intrinsics K(1024, 768, 800.5, 780.25, 530.3, 370.8, 1.5);
  EXPECT_EQ(K.width(), 1024);
  EXPECT_EQ(K.height(), 768);
  EXPECT_EQ(K.fx(), 800.5);
  EXPECT_EQ(K.fy(), 780.25);
  EXPECT_EQ(K.cx(), 530.3);
  EXPECT_EQ(K.cy(), 370.8);
  EXPECT_EQ(K.skew(), 1.5);
  Eigen::Matrix3d expected;
  expected << 800.5, 1.5, 530.3, 0, 780.25, 370.8, 0, 0, 1;
  EXPECT_EQ(K.Matrix(), expected);
  EXPECT_EQ(Intrinsics::FromMatrix(expected, 1024, 768), K);
  EXPECT_NE(Intrinsics(1024, 768, 800.5, 780.25, 530.3, 370.8), K);
  // The principal point may lie anywhere, even off the image.
  EXPECT_NO_THROW(Intrinsics(640, 480, 500, 500, -100.0, 900.0, -3.0));
}

struct BadCase {
  std::string field;
  std::string value;
  std::function<void()> make;
};

TEST(Intrinsics, RejectsBadFieldsNamingFieldAndValue) {
  const std::vector<BadCase> cases = {
      {"width", "got 0", [] { Intrinsics(0, 480, 500, 500, 320, 240); }},
      {"width", "got -640", [] { Intrinsics(-640, 480, 500, 500, 320, 240); }},
      {"height", "got 0", [] { Intrinsics(640, 0, 500, 500, 320, 240); }},
      {"height", "got -1", [] { Intrinsics(640, -1, 500, 500, 320, 240); }},
      {"fx", "got -3", [] { Intrinsics(640, 480, -3, 500, 320, 240); }},
      {"fx", "got 0", [] { Intrinsics(640, 480, 0.0, 500, 320, 240); }},
      {"fx", "got nan", [] { Intrinsics(640, 480, kNan, 500, 320, 240); }},
      {"fx", "got inf", [] { Intrinsics(640, 480, kInf, 500, 320, 240); }},
      {"fy", "got -0.5", [] { Intrinsics(640, 480, 500, -0.5, 320, 240); }},
      {"fy", "got 0", [] { Intrinsics(640, 480, 500, 0.0, 320, 240); }},
      {"fy", "got nan", [] { Intrinsics(640, 480, 500, kNan, 320, 240); }},
      {"fy", "got inf", [] { Intrinsics(640, 480, 500, kInf, 320, 240); }},
      {"cx", "got nan", [] { Intrinsics(640, 480, 500, 500, kNan, 240); }},
      {"cx", "got -inf", [] { Intrinsics(640, 480, 500, 500, -kInf, 240); }},
      {"cy", "got nan", [] { Intrinsics(640, 480, 500, 500, 320, kNan); }},
      {"cy", "got inf", [] { Intrinsics(640, 480, 500, 500, 320, kInf); }},
      {"skew", "got nan", [] { Intrinsics(640, 480, 500, 500, 320, 240, kNan); }},
      {"skew", "got inf", [] { Intrinsics(640, 480, 500, 500, 320, 240, kInf); }},
  };
  for (const BadCase& c : cases) {
    EXPECT_THAT(ThrownMessage(c.make),
                AllOf(StartsWith("Intrinsics: " + c.field + " must be"), HasSubstr(c.value)));
  }
  EXPECT_EQ(ThrownMessage([] { Intrinsics(640, 480, -3, 500, 320, 240); }),
            "Intrinsics: fx must be a positive finite number, got -3");
}

TEST(Intrinsics, FromMatrixRejectsAnotherKindOfMatrix) {
  Eigen::Matrix3d K;
  K << 500, 0, 320, 0, 500, 240, 0, 0, 1;
  Eigen::Matrix3d bad = K;
  bad(1, 0) = 0.5;
  EXPECT_THAT(ThrownMessage([&] { Intrinsics::FromMatrix(bad, 640, 480); }),
              AllOf(StartsWith("Intrinsics::FromMatrix:"), HasSubstr("K(1,0) must be 0"),
                    HasSubstr("got 0.5")));
  bad = K;
  bad(2, 2) = 2.0;  // a scaled K
  EXPECT_THAT(ThrownMessage([&] { Intrinsics::FromMatrix(bad, 640, 480); }),
              AllOf(HasSubstr("K(2,2) must be 1"), HasSubstr("got 2")));
  bad = K;
  bad(2, 0) = kNan;
  EXPECT_THAT(ThrownMessage([&] { Intrinsics::FromMatrix(bad, 640, 480); }),
              AllOf(HasSubstr("K(2,0)"), HasSubstr("got nan")));
  bad = K;
  bad(1, 1) = -500;
  EXPECT_THAT(ThrownMessage([&] { Intrinsics::FromMatrix(bad, 640, 480); }),
              AllOf(StartsWith("Intrinsics::FromMatrix: fy"), HasSubstr("got -500")));
  EXPECT_THAT(ThrownMessage([&] { Intrinsics::FromMatrix(K, 640, 0); }),
              AllOf(StartsWith("Intrinsics::FromMatrix: height"), HasSubstr("got 0")));
}

TEST(Intrinsics, NormalizedToPixelMatchesCvProjectPoints) {
  const Intrinsics K(1024, 768, 800.0, 780.0, 530.3, 370.8);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> coordinate(-1.5, 1.5);
  std::vector<cv::Point3d> object;
  std::vector<Vector2d> xy;
  for (int i = 0; i < kSamples; ++i) {
    xy.emplace_back(coordinate(rng), coordinate(rng));
    object.emplace_back(xy.back().x(), xy.back().y(), 1.0);
  }
  std::vector<cv::Point2d> image;
  cv::projectPoints(object, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), CvMatrix(K), cv::noArray(),
                    image);
  double worst = 0.0;
  for (size_t i = 0; i < xy.size(); ++i) {
    const double error = (K.NormalizedToPixel(xy[i]) - Vector2d(image[i].x, image[i].y)).norm();
    worst = std::max(worst, error);
    EXPECT_LE(error, kPixelTolerance);
  }
  std::printf("[ measured ] NormalizedToPixel vs cv::projectPoints: worst %.3g px\n", worst);
}

TEST(Intrinsics, SkewIsAppliedAsTheMatrixK) {
  // cv::projectPoints ignores skew; the reference is the product K (xd, yd, 1) with cv::Matx.
  const Intrinsics K(1024, 768, 800.0, 780.0, 530.3, 370.8, -4.25);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> coordinate(-1.5, 1.5);
  for (int i = 0; i < kSamples; ++i) {
    const Vector2d xd(coordinate(rng), coordinate(rng));
    const cv::Vec3d reference = CvMatrix(K) * cv::Vec3d(xd.x(), xd.y(), 1.0);
    EXPECT_LE((K.NormalizedToPixel(xd) - Vector2d(reference[0], reference[1])).norm(),
              kPixelTolerance);
  }
  // Sign: positive y (below the axis) with negative skew moves left.
  EXPECT_LT(K.NormalizedToPixel({0.0, 0.5}).x(), K.cx());
}

TEST(Intrinsics, PixelToNormalizedInvertsKAsOpenCvDoes) {
  for (double skew : {0.0, 3.5}) {
    const Intrinsics K(1000, 333, 700.0, 710.0, 480.2, 170.9, skew);
    const cv::Matx33d K_inv = CvMatrix(K).inv();
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-0.5, 999.5), v(-0.5, 332.5);
    std::vector<cv::Point2d> pixels = {{-0.5, -0.5}, {999.5, 332.5}};
    for (int i = 0; i < kSamples; ++i) pixels.emplace_back(u(rng), v(rng));
    for (const cv::Point2d& p : pixels) {
      const Vector2d xd = K.PixelToNormalized({p.x, p.y});
      const cv::Vec3d reference = K_inv * cv::Vec3d(p.x, p.y, 1.0);
      EXPECT_LE((xd - Vector2d(reference[0], reference[1])).norm(), kNormalizedTolerance);
      EXPECT_LE((K.NormalizedToPixel(xd) - Vector2d(p.x, p.y)).norm(), kPixelTolerance);
    }
    if (skew == 0.0) {
      // cv::undistortPoints with no distortion is K^-1 (it reads no skew).
      std::vector<cv::Point2d> normalized;
      cv::undistortPoints(pixels, normalized, CvMatrix(K), cv::noArray());
      for (size_t i = 0; i < pixels.size(); ++i) {
        EXPECT_LE((K.PixelToNormalized({pixels[i].x, pixels[i].y}) -
                   Vector2d(normalized[i].x, normalized[i].y))
                      .norm(),
                  kNormalizedTolerance);
      }
    }
  }
}

double AngleBetweenRays(const cv::Matx33d& K_inv, double u0, double v0, double u1, double v1) {
  const cv::Vec3d a = K_inv * cv::Vec3d(u0, v0, 1.0), b = K_inv * cv::Vec3d(u1, v1, 1.0);
  return std::atan2(cv::norm(a.cross(b)), a.dot(b));
}

TEST(Intrinsics, FieldOfViewSpansThePixelEdges) {
  for (const Intrinsics& K :
       {Intrinsics(1024, 768, 800.0, 780.0, 530.3, 370.8),
        Intrinsics(640, 480, 300.0, 310.0, -50.0, 600.0), Intrinsics(1, 1, 1.0, 2.0, 0.0, 0.0)}) {
    const cv::Matx33d K_inv = CvMatrix(K).inv();
    const double w = K.width(), h = K.height();
    EXPECT_NEAR(K.HorizontalFov(), AngleBetweenRays(K_inv, -0.5, K.cy(), w - 0.5, K.cy()),
                kAngleTolerance);
    EXPECT_NEAR(K.VerticalFov(), AngleBetweenRays(K_inv, K.cx(), -0.5, K.cx(), h - 0.5),
                kAngleTolerance);
  }
  // A centred 90 degree camera: width = 2 fx.
  const Intrinsics centred(1000, 500, 500.0, 250.0, 499.5, 249.5);
  EXPECT_NEAR(centred.HorizontalFov(), std::numbers::pi / 2, kAngleTolerance);
  EXPECT_NEAR(centred.VerticalFov(), std::numbers::pi / 2, kAngleTolerance);
}

}  // namespace
}  // namespace saccade::geometry
