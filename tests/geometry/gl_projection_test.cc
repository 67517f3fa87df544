// The OpenGL projection of K, checked by running OpenGL's fixed-function arithmetic (clip space,
// perspective divide, viewport transform) in the test and comparing the window coordinates,
// turned into OpenCV pixels, with cv::projectPoints.

#include "saccade/geometry/gl_projection.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <random>
#include <string>
#include <vector>

#include "saccade/core/error.h"

namespace saccade::geometry {
namespace {

using Eigen::Matrix4d;
using Eigen::Vector2d;
using Eigen::Vector3d;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::StartsWith;

// Window coordinates go through a 4x4 product, a divide and the viewport scale on values up to
// ~1e3: a few 1e-13 px of rounding. 1e-9 px is the brief's bar; a wrong half pixel or a
// mirrored principal point is off by >= 0.5 px.
constexpr double kPixelTolerance = 1e-9;
// K -> P -> K: each entry goes through one division and one multiplication by the image size
// (cx, cy: also a subtraction of numbers of the size of the image), so the error is a few ulps
// of max(|value|, image size).
constexpr double kRoundTripRelative = 1e-12;
// Clip planes: recovering far divides by P(2,2) + 1 = -2 near / (far - near), which cancels
// about log10(far / near) digits: with far / near <= 1e5 the error reaches ~2e-11.
constexpr double kClipRoundTripRelative = 1e-10;
// NDC depth at the clip planes: one rational expression, ~1e-15.
constexpr double kNdcTolerance = 1e-12;
constexpr int kSamples = 2000;

struct Case {
  std::string name;
  Intrinsics K;
};

std::vector<Case> Cases() {
  return {
      {"1024x768", Intrinsics(1024, 768, 900.0, 870.0, 530.7, 371.2)},
      {"1024x768 skew", Intrinsics(1024, 768, 900.0, 870.0, 530.7, 371.2, 2.5)},
      {"1000x333", Intrinsics(1000, 333, 700.0, 710.0, 480.2, 170.9)},
      {"641x479 skew", Intrinsics(641, 479, 512.3, 498.7, 322.9, 236.1, -1.3)},
      {"1x1", Intrinsics(1, 1, 1.0, 1.5, 0.0, 0.0)},
  };
}

const ClipPlanes kClip{0.05, 250.0};

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

struct Gl {
  Vector2d window;
  double ndc_z;
};

// What OpenGL does with a vertex: eye = (X, -Y, -Z), clip = P eye, NDC = clip / w, and
// glViewport(0, 0, width, height): window = (NDC + 1) * size / 2.
Gl RunGl(const Matrix4d& P, const Vector3d& p_C, int width, int height) {
  const Eigen::Vector4d clip = P * Eigen::Vector4d(p_C.x(), -p_C.y(), -p_C.z(), 1.0);
  const Vector3d ndc = clip.head<3>() / clip.w();
  return {{(ndc.x() + 1.0) * width / 2.0, (ndc.y() + 1.0) * height / 2.0}, ndc.z()};
}

// OpenCV pixel of a window position: framebuffer row 0 is the bottom row, unless flipped.
Vector2d PixelOfWindow(const Vector2d& window, int height, bool flip_rows) {
  return {window.x() - 0.5, flip_rows ? window.y() - 0.5 : height - window.y() - 0.5};
}

// Points at random depths whose pixels cover the whole image, corners included (through
// OpenCV's K^-1).
std::vector<Vector3d> PointsCoveringImage(const Intrinsics& K, unsigned seed) {
  const double w = K.width(), h = K.height();
  std::vector<Vector2d> pixels = {{-0.5, -0.5},       {w - 0.5, -0.5}, {-0.5, h - 0.5},
                                  {w - 0.5, h - 0.5}, {0.0, 0.0},      {w - 1.0, h - 1.0}};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.5, w - 0.5), v(-0.5, h - 0.5),
      depth(kClip.near, kClip.far);
  for (int i = 0; i < kSamples; ++i) pixels.emplace_back(u(rng), v(rng));
  const cv::Matx33d K_inv = CvMatrix(K).inv();
  std::vector<Vector3d> points;
  for (const Vector2d& px : pixels) {
    const cv::Vec3d ray = K_inv * cv::Vec3d(px.x(), px.y(), 1.0);
    const double z = depth(rng);
    points.emplace_back(ray[0] / ray[2] * z, ray[1] / ray[2] * z, z);
  }
  return points;
}

// cv::projectPoints (zero distortion). It reads no skew from the camera matrix, so with skew
// the reference is cv::projectPoints with an identity camera matrix followed by K with skew.
std::vector<Vector2d> OpenCvPixels(const Intrinsics& K, const std::vector<Vector3d>& points) {
  std::vector<cv::Point3d> object;
  for (const Vector3d& p : points) object.emplace_back(p.x(), p.y(), p.z());
  std::vector<cv::Point2d> image;
  const cv::Vec3d zero(0, 0, 0);
  std::vector<Vector2d> out;
  if (K.skew() == 0.0) {
    cv::projectPoints(object, zero, zero, CvMatrix(K), cv::noArray(), image);
    for (const cv::Point2d& p : image) out.emplace_back(p.x, p.y);
  } else {
    cv::projectPoints(object, zero, zero, cv::Matx33d::eye(), cv::noArray(), image);
    for (const cv::Point2d& p : image) {
      const cv::Vec3d q = CvMatrix(K) * cv::Vec3d(p.x, p.y, 1.0);
      out.emplace_back(q[0], q[1]);
    }
  }
  return out;
}

void ExpectGlMatchesOpenCv(bool flip_rows) {
  unsigned seed = flip_rows ? 20 : 10;
  for (const Case& c : Cases()) {
    SCOPED_TRACE(c.name);
    const Matrix4d P = GlProjectionFromIntrinsics(c.K, kClip, flip_rows);
    const std::vector<Vector3d> points = PointsCoveringImage(c.K, seed++);
    const std::vector<Vector2d> reference = OpenCvPixels(c.K, points);
    double worst = 0.0;
    for (size_t i = 0; i < points.size(); ++i) {
      const Gl gl = RunGl(P, points[i], c.K.width(), c.K.height());
      const Vector2d pixel = PixelOfWindow(gl.window, c.K.height(), flip_rows);
      const double error = (pixel - reference[i]).norm();
      worst = std::max(worst, error);
      EXPECT_LE(error, kPixelTolerance)
          << "point " << points[i].transpose() << " GL " << pixel.transpose() << " OpenCV "
          << reference[i].transpose();
      EXPECT_GE(gl.ndc_z, -1.0 - kNdcTolerance);
      EXPECT_LE(gl.ndc_z, 1.0 + kNdcTolerance);
    }
    std::printf("[ measured ] %s%s GL pixel vs cv::projectPoints: worst %.3g px\n", c.name.c_str(),
                flip_rows ? " flipped" : "", worst);
  }
}

TEST(GlProjection, WindowCoordinatesMatchCvProjectPoints) { ExpectGlMatchesOpenCv(false); }

TEST(GlProjection, FlippedRowsPutImageRowZeroAtWindowRowZero) { ExpectGlMatchesOpenCv(true); }

TEST(GlProjection, NdcDepthMapsNearToMinusOneAndFarToPlusOne) {
  for (bool flip : {false, true}) {
    const Intrinsics K = Cases()[1].K;
    const Matrix4d P = GlProjectionFromIntrinsics(K, kClip, flip);
    for (const Vector2d& lateral : {Vector2d(0, 0), Vector2d(0.3, -0.2), Vector2d(-0.6, 0.4)}) {
      const auto at = [&](double z) {
        return RunGl(P, Vector3d(lateral.x() * z, lateral.y() * z, z), K.width(), K.height()).ndc_z;
      };
      EXPECT_NEAR(at(kClip.near), -1.0, kNdcTolerance);
      EXPECT_NEAR(at(kClip.far), 1.0, kNdcTolerance);
      EXPECT_LT(at(0.5 * kClip.near), -1.0) << "in front of the near plane: clipped";
      EXPECT_GT(at(2.0 * kClip.far), 1.0) << "beyond the far plane: clipped";
      double previous = -1.0;
      for (double z = 2 * kClip.near; z < kClip.far; z *= 1.5) {
        EXPECT_GT(at(z), previous) << "depth must grow with distance";
        previous = at(z);
      }
    }
  }
}

// The principal point's row counts from the top in OpenCV and from the bottom in OpenGL: a
// point on the optical axis lands on window row height - cy - 0.5 (not cy + 0.5, which is what
// a projection built with cy as if measured from the bottom gives).
TEST(GlProjection, PrincipalPointRowIsMeasuredFromTheTop) {
  for (const Intrinsics& K : {Intrinsics(1024, 768, 900.0, 870.0, 530.7, 100.25),
                              Intrinsics(1000, 333, 700.0, 710.0, 480.2, 300.75)}) {
    const Gl gl =
        RunGl(GlProjectionFromIntrinsics(K, kClip), {0.0, 0.0, 3.0}, K.width(), K.height());
    EXPECT_NEAR(gl.window.y(), K.height() - K.cy() - 0.5, kPixelTolerance);
    EXPECT_NEAR(gl.window.x(), K.cx() + 0.5, kPixelTolerance);
    EXPECT_GT(std::abs(gl.window.y() - (K.cy() + 0.5)), 100.0);
  }
}

// Pixel centres: OpenCV's (0, 0) is the centre of the top-left pixel, i.e. window (0.5, h - 0.5).
TEST(GlProjection, PixelCentresAreHalfAPixelFromTheWindowOrigin) {
  for (const Case& c : Cases()) {
    SCOPED_TRACE(c.name);
    const int w = c.K.width(), h = c.K.height();
    const cv::Matx33d K_inv = CvMatrix(c.K).inv();
    const auto point_on_pixel = [&](double u, double v) {
      const cv::Vec3d ray = K_inv * cv::Vec3d(u, v, 1.0);
      return Vector3d(ray[0] / ray[2] * 2.0, ray[1] / ray[2] * 2.0, 2.0);
    };
    const Matrix4d P = GlProjectionFromIntrinsics(c.K, kClip);
    const Gl top_left = RunGl(P, point_on_pixel(0.0, 0.0), w, h);
    EXPECT_NEAR(top_left.window.x(), 0.5, kPixelTolerance);
    EXPECT_NEAR(top_left.window.y(), h - 0.5, kPixelTolerance);
    const Gl bottom_right = RunGl(P, point_on_pixel(w - 1.0, h - 1.0), w, h);
    EXPECT_NEAR(bottom_right.window.x(), w - 0.5, kPixelTolerance);
    EXPECT_NEAR(bottom_right.window.y(), 0.5, kPixelTolerance);
    const Gl flipped =
        RunGl(GlProjectionFromIntrinsics(c.K, kClip, true), point_on_pixel(0.0, 0.0), w, h);
    EXPECT_NEAR(flipped.window.x(), 0.5, kPixelTolerance);
    EXPECT_NEAR(flipped.window.y(), 0.5, kPixelTolerance);
  }
}

// u = fx x + skew y + cx: with positive skew, a point below the axis (y > 0) moves right.
TEST(GlProjection, PositiveSkewMovesPointsBelowTheAxisRight) {
  const Intrinsics plain(1024, 768, 900.0, 870.0, 530.7, 371.2);
  const Intrinsics skewed(1024, 768, 900.0, 870.0, 530.7, 371.2, 25.0);
  const Vector3d below(0.1, 0.5, 2.0);  // x = 0.05, y = 0.25
  const Gl a = RunGl(GlProjectionFromIntrinsics(plain, kClip), below, 1024, 768);
  const Gl b = RunGl(GlProjectionFromIntrinsics(skewed, kClip), below, 1024, 768);
  EXPECT_NEAR(b.window.x() - a.window.x(), 25.0 * 0.25, kPixelTolerance);
  EXPECT_NEAR(b.window.y(), a.window.y(), kPixelTolerance);
  EXPECT_NEAR(b.window.x(), 900.0 * 0.05 + 25.0 * 0.25 + 530.7 + 0.5, kPixelTolerance);
}

TEST(GlProjection, IntrinsicsRoundTripThroughTheProjection) {
  std::mt19937 rng(30);
  std::uniform_int_distribution<int> size(1, 4096);
  std::uniform_real_distribution<double> focal(0.5, 5000.0), unit(-1.0, 2.0), skew(-20.0, 20.0),
      log_near(-3.0, 0.0), log_ratio(0.5, 5.0);
  std::vector<std::pair<int, int>> sizes = {{1024, 768}, {1000, 333}, {641, 479}, {1, 1}};
  for (int i = 0; i < kSamples; ++i) sizes.emplace_back(size(rng), size(rng));
  double worst = 0.0, worst_clip = 0.0;
  for (const auto& [w, h] : sizes) {
    const Intrinsics K(w, h, focal(rng), focal(rng), unit(rng) * w, unit(rng) * h, skew(rng));
    ClipPlanes clip;
    clip.near = std::pow(10.0, log_near(rng));
    clip.far = clip.near * std::pow(10.0, log_ratio(rng));
    for (bool flip : {false, true}) {
      const Matrix4d P = GlProjectionFromIntrinsics(K, clip, flip);
      const Intrinsics back = IntrinsicsFromGlProjection(P, w, h, flip);
      EXPECT_EQ(back.width(), w);
      EXPECT_EQ(back.height(), h);
      const double errors[] = {
          std::abs(back.fx() - K.fx()) / K.fx(),
          std::abs(back.fy() - K.fy()) / K.fy(),
          std::abs(back.cx() - K.cx()) / std::max<double>(std::abs(K.cx()), w),
          std::abs(back.cy() - K.cy()) / std::max<double>(std::abs(K.cy()), h),
          std::abs(back.skew() - K.skew()) / std::max(std::abs(K.skew()), 1.0),
      };
      for (double e : errors) {
        worst = std::max(worst, e);
        EXPECT_LE(e, kRoundTripRelative) << w << "x" << h << " fx " << K.fx() << " cx " << K.cx();
      }
      const ClipPlanes clip_back = ClipPlanesFromGlProjection(P);
      const double clip_error = std::max(std::abs(clip_back.near - clip.near) / clip.near,
                                         std::abs(clip_back.far - clip.far) / clip.far);
      worst_clip = std::max(worst_clip, clip_error);
      EXPECT_LE(clip_error, kClipRoundTripRelative) << clip.near << " " << clip.far;
    }
  }
  std::printf("[ measured ] K -> P -> K worst relative %.3g; clip planes worst relative %.3g\n",
              worst, worst_clip);
}

TEST(GlProjection, RejectsBadClipPlanesNamingThem) {
  const Intrinsics K = Cases()[0].K;
  const double inf = std::numeric_limits<double>::infinity();
  for (const ClipPlanes& clip :
       {ClipPlanes{0.0, 10.0}, ClipPlanes{-1.0, 10.0}, ClipPlanes{5.0, 5.0}, ClipPlanes{10.0, 5.0},
        ClipPlanes{0.1, inf}, ClipPlanes{std::nan(""), 10.0}}) {
    EXPECT_THAT(ThrownMessage([&] { GlProjectionFromIntrinsics(K, clip); }),
                AllOf(StartsWith("GlProjectionFromIntrinsics:"), HasSubstr("0 < near < far"),
                      HasSubstr(fmt::format("near = {}", clip.near)),
                      HasSubstr(fmt::format("far = {}", clip.far))));
  }
}

TEST(GlProjection, IntrinsicsFromProjectionRejectsOtherMatrices) {
  const Intrinsics K = Cases()[1].K;
  const Matrix4d P = GlProjectionFromIntrinsics(K, kClip);
  const auto message = [&](const Matrix4d& m, bool flip = false) {
    return ThrownMessage([&] { IntrinsicsFromGlProjection(m, 1024, 768, flip); });
  };
  Matrix4d m = P;
  m(3, 2) = 1.0;  // a projection looking down +z
  EXPECT_THAT(message(m), AllOf(StartsWith("IntrinsicsFromGlProjection:"), HasSubstr("P(3,2)"),
                                HasSubstr("must be -1"), HasSubstr("got 1")));
  m = P;
  m(1, 0) = 0.125;
  EXPECT_THAT(message(m), AllOf(HasSubstr("P(1,0)"), HasSubstr("must be 0"), HasSubstr("0.125")));
  m = P;
  m(3, 3) = 1.0;
  m(3, 2) = 0.0;  // orthographic
  EXPECT_THAT(message(m), HasSubstr("P(3,2)"));
  m = P;
  m(0, 3) = 0.5;  // an off-axis shift in eye space
  EXPECT_THAT(message(m), AllOf(HasSubstr("P(0,3)"), HasSubstr("0.5")));
  m = P;
  m(0, 2) = std::nan("");
  EXPECT_THAT(message(m), AllOf(HasSubstr("P(0,2)"), HasSubstr("finite"), HasSubstr("nan")));
  m = P;
  m(0, 0) = -m(0, 0);
  EXPECT_THAT(message(m), AllOf(HasSubstr("P(0,0)"), HasSubstr("positive")));
  // A flipped matrix read as unflipped: fy would come out negative.
  EXPECT_THAT(message(GlProjectionFromIntrinsics(K, kClip, true)),
              AllOf(HasSubstr("P(1,1)"), HasSubstr("flip_rows")));
  EXPECT_THAT(message(P, true), AllOf(HasSubstr("P(1,1)"), HasSubstr("negative")));
  EXPECT_THAT(ThrownMessage([&] { IntrinsicsFromGlProjection(P, 0, 768); }),
              AllOf(HasSubstr("width and height"), HasSubstr("got 0 x 768")));
  EXPECT_THAT(ThrownMessage([&] { IntrinsicsFromGlProjection(P, 1024, -2); }),
              HasSubstr("got 1024 x -2"));
  m = P;
  m(2, 3) = 0.0;  // no clip planes can be read from this
  EXPECT_THAT(ThrownMessage([&] { ClipPlanesFromGlProjection(m); }),
              AllOf(StartsWith("ClipPlanesFromGlProjection:"), HasSubstr("P(2,3) = 0")));
}

TEST(GlProjection, FrameAndWindowHelpers) {
  EXPECT_EQ(OpticalToGlEye(), Vector3d(1.0, -1.0, -1.0).asDiagonal().toDenseMatrix());
  const Matrix4d P = GlProjectionFromIntrinsics(Cases()[1].K, kClip);
  const Vector3d p(0.3, -0.4, 2.0);
  Eigen::Vector4d eye;
  eye << OpticalToGlEye() * p, 1.0;
  EXPECT_EQ(P * eye, P * Eigen::Vector4d(0.3, 0.4, -2.0, 1.0));
  EXPECT_EQ(WindowToPixel({0.5, 767.5}, 768), Vector2d(0.0, 0.0));
  EXPECT_EQ(PixelToWindow({0.0, 0.0}, 768), Vector2d(0.5, 767.5));
  EXPECT_EQ(PixelToWindow({1023.0, 767.0}, 768), Vector2d(1023.5, 0.5));
  std::mt19937 rng(40);
  std::uniform_real_distribution<double> coordinate(-10.0, 2000.0);
  for (int i = 0; i < 100; ++i) {
    const Vector2d pixel(coordinate(rng), coordinate(rng));
    EXPECT_LE((WindowToPixel(PixelToWindow(pixel, 333), 333) - pixel).norm(), 1e-12);
  }
}

}  // namespace
}  // namespace saccade::geometry
