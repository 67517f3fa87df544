// Rendered pixels land where OpenCV projects them (DESIGN.md: "the simulator's pixels land where
// OpenCV says they must"): small smooth markers at known 3D points, seen by a world camera with
// an off-centre principal point, fx != fy and skew, at an even and at an odd image size. Each
// marker's intensity-weighted centroid in the rendered image is compared to cv::projectPoints
// of the marker's centre.
//
// The markers and why they measure the projection and nothing else:
// - Each marker is a picture (scene::MakePicture) of a Gaussian blob, placed fronto-parallel:
//   its plane is at constant depth Z in the camera frame. A plane at constant depth maps to the
//   image by an AFFINE map (u = (fx X + s Y) / Z + cx, v = fy Y / Z + cy), and an affine map
//   sends the centroid of an intensity pattern to the centroid of its image: no perspective
//   bias. (A sphere would have one: its image is an ellipse whose centre lies
//   f tan(theta) sin^2(alpha) / cos^2(theta) beyond the projection of its centre, for angular
//   radius alpha at angle theta off the axis; at a corner of this camera (theta ~ 35 deg) a
//   sphere 10 px across is off by ~0.03 px, most of the error budget.)
// - The blob is smooth (sigma ~ 1.7 px on screen) and point-symmetric about the texture's centre,
//   as are all its mipmap levels, so the rendered intensity is point-symmetric about the
//   projected centre: no hard edges to alias, and sampling it at pixel centres moves the
//   centroid only by the (tiny) aliasing of a smooth function.
// - 8-bit quantisation adds a random +-0.5 LSB a pixel: on a blob of peak 255 and sigma 2 px
//   the centroid moves by ~0.003 px RMS, 0.008 px at most (simulated over sub-pixel phases).
// - Vertex positions go through float matrices built in double (model-view computed in double
//   on the CPU), and llvmpipe snaps vertices to 1/256 px: both far below 0.01 px.
// Black background, no ground, ambient light only: the image is the blobs and zeros.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <random>
#include <string>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/core/image_io.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/pose.h"
#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"

namespace saccade::render {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// Required accuracy: the RMS over all markers of |centroid - OpenCV's pixel|. 0.05 px is what
// sub-pixel feature detectors and calibration residuals work at; the biases above add up to
// well under 0.01 px, so a larger error is a real misplacement (a half-pixel convention, a
// principal point, skew or row-flip error shows as >= 0.1 px, mostly far more).
constexpr double kMaxRmsErrorPx = 0.05;
// No single marker may be off by more than this: a local error (one corner, one depth) that the
// RMS would dilute.
constexpr double kMaxErrorPx = 0.1;

// The marker texture: kTexels square, a Gaussian of kSigmaTexels about its centre, zero (after
// rounding) at its border so that the picture's edges are invisible.
constexpr int kTexels = 64;
constexpr double kSigmaTexels = 8.0;
// On screen the picture is about kMarkerPx pixels high (sigma ~ 1.7 px), whatever its depth.
// Not a power-of-two fraction of kTexels: with texels landing 1:1 on pixels, every pixel
// samples its mipmap level at the same sub-texel phase and the (small, phase-dependent)
// errors of the filter add up instead of averaging out.
constexpr double kMarkerPx = 13.7;
// Centroid window half size: the picture's half diagonal on screen and a margin.
constexpr int kWindow = 12;
// Marker centres keep this far from the image border so that their windows fit.
constexpr double kBorderPx = 12.5;

std::shared_ptr<const scene::Texture> GaussianTexture() {
  auto texture = std::make_shared<scene::Texture>();
  texture->source = "gaussian marker";
  texture->image = Image(kTexels, kTexels, PixelFormat::kRgb8);
  const double c = 0.5 * (kTexels - 1);
  for (int y = 0; y < kTexels; ++y) {
    for (int x = 0; x < kTexels; ++x) {
      const double r2 = (x - c) * (x - c) + (y - c) * (y - c);
      const auto value = static_cast<uint8_t>(
          std::lround(255.0 * std::exp(-r2 / (2.0 * kSigmaTexels * kSigmaTexels))));
      uint8_t* pixel = texture->image.row(y) + 3 * x;
      pixel[0] = pixel[1] = pixel[2] = value;
    }
  }
  return texture;
}

struct Case {
  std::string name;
  geometry::Intrinsics K;
  int msaa;
};

std::ostream& operator<<(std::ostream& os, const Case& c) { return os << c.name; }

struct Marker {
  Vector3d p_W;
  Vector2d expected;  // OpenCV's pixel
  Vector2d measured = Vector2d::Zero();
  double mass = 0.0;
  double error = 0.0;
};

// OpenCV's pixels of world points for a camera at X_WC with K (skew included):
// cv::projectPoints reads no skew from its camera matrix, so it projects with an identity
// matrix to normalized coordinates and K (with skew) is applied after, as in
// tests/geometry/camera_model_test.cc.
std::vector<Vector2d> OpenCvProject(const geometry::Intrinsics& K, const geometry::Pose& X_WC,
                                    const std::vector<Vector3d>& points_W) {
  const geometry::Pose X_CW = X_WC.inverse();
  cv::Matx33d R;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R(r, c) = X_CW.linear()(r, c);
  }
  cv::Vec3d rvec;
  cv::Rodrigues(R, rvec);
  const cv::Vec3d tvec(X_CW.translation().x(), X_CW.translation().y(), X_CW.translation().z());
  std::vector<cv::Point3d> object;
  for (const Vector3d& p : points_W) object.emplace_back(p.x(), p.y(), p.z());
  std::vector<cv::Point2d> normalized;
  cv::projectPoints(object, rvec, tvec, cv::Matx33d::eye(), cv::noArray(), normalized);
  const cv::Matx33d Kcv(K.fx(), K.skew(), K.cx(), 0.0, K.fy(), K.cy(), 0.0, 0.0, 1.0);
  std::vector<Vector2d> out;
  for (const cv::Point2d& p : normalized) {
    const cv::Vec3d q = Kcv * cv::Vec3d(p.x, p.y, 1.0);
    out.emplace_back(q[0] / q[2], q[1] / q[2]);
  }
  return out;
}

// An image showing the error field: the render in grey, each marker's error x 100 as a red
// line from OpenCV's pixel (green).
Image Annotate(const Image& render, const std::vector<Marker>& markers) {
  Image out(render.width(), render.height(), PixelFormat::kRgb8);
  for (int y = 0; y < render.height(); ++y) {
    for (int x = 0; x < render.width(); ++x) {
      const uint8_t g = static_cast<uint8_t>(render.row(y)[3 * x + 1] / 2);
      out.row(y)[3 * x] = out.row(y)[3 * x + 1] = out.row(y)[3 * x + 2] = g;
    }
  }
  const auto put = [&out](double x, double y, uint8_t r, uint8_t g, uint8_t b) {
    const long ix = std::lround(x), iy = std::lround(y);
    if (ix < 0 || iy < 0 || ix >= out.width() || iy >= out.height()) return;
    uint8_t* p = out.row(static_cast<int>(iy)) + 3 * ix;
    p[0] = r;
    p[1] = g;
    p[2] = b;
  };
  for (const Marker& m : markers) {
    const Vector2d d = 100.0 * (m.measured - m.expected);
    const int steps = static_cast<int>(std::ceil(d.norm())) + 1;
    for (int i = 0; i <= steps; ++i) {
      const Vector2d p = m.expected + d * (static_cast<double>(i) / steps);
      put(p.x(), p.y(), 255, 0, 0);
    }
    put(m.expected.x(), m.expected.y(), 0, 255, 0);
  }
  return out;
}

class MarkerAccuracyTest : public ::testing::TestWithParam<Case> {};

TEST_P(MarkerAccuracyTest, CentroidsMatchOpenCvProjection) {
  const Case& param = GetParam();
  const geometry::Intrinsics& K = param.K;
  // A camera metres from the origin, in a general orientation.
  const geometry::Pose X_WC =
      geometry::MakePose(geometry::RotationFromRpy(-1.9, 0.15, 2.4), Vector3d(3.2, -1.7, 1.4));

  // Markers on a jittered grid that covers the whole image up to kBorderPx from its edges,
  // corners included, at depths from 1.5 m to 8 m.
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> jitter(-0.5, 0.5), depth(1.5, 8.0);
  constexpr int kColumns = 9, kRows = 7;
  const Eigen::Matrix3d K_inverse = K.Matrix().inverse();
  auto texture = GaussianTexture();
  std::vector<scene::Object> objects;
  std::vector<Marker> markers;
  for (int row = 0; row < kRows; ++row) {
    for (int column = 0; column < kColumns; ++column) {
      const double span_u = K.width() - 1 - 2 * kBorderPx, span_v = K.height() - 1 - 2 * kBorderPx;
      double u = kBorderPx + span_u * column / (kColumns - 1) + jitter(rng);
      double v = kBorderPx + span_v * row / (kRows - 1) + jitter(rng);
      u = std::clamp(u, kBorderPx, K.width() - 1 - kBorderPx);
      v = std::clamp(v, kBorderPx, K.height() - 1 - kBorderPx);
      const double Z = depth(rng);
      const Vector3d p_C = Z * (K_inverse * Vector3d(u, v, 1.0));
      // The picture faces the camera (its +x towards -z_C), upright in the image (its top, +z,
      // towards -y_C), its right edge along +x_C: fronto-parallel.
      Eigen::Matrix3d R_CO;
      R_CO.col(0) = -Vector3d::UnitZ();
      R_CO.col(1) = Vector3d::UnitX();
      R_CO.col(2) = -Vector3d::UnitY();
      const geometry::Pose X_WO = X_WC * geometry::MakePose(R_CO, p_C);
      scene::Object object;
      object.name = "marker" + std::to_string(markers.size());
      object.id = static_cast<uint32_t>(markers.size() + 1);
      object.model = scene::MakePicture(texture, kMarkerPx * Z / K.fy());
      object.motion = scene::Motion::Static(X_WO);
      objects.push_back(object);
      markers.push_back(Marker{X_WO.translation(), Vector2d::Zero()});
    }
  }
  std::vector<Vector3d> points_W;
  for (const Marker& m : markers) points_W.push_back(m.p_W);
  const std::vector<Vector2d> expected = OpenCvProject(K, X_WC, points_W);
  for (std::size_t i = 0; i < markers.size(); ++i) markers[i].expected = expected[i];

  scene::CameraSpec camera{"world", geometry::CameraModel(K),        scene::CameraMount::kWorld,
                           X_WC,    geometry::ClipPlanes{0.1, 20.0}, scene::SensorSpec{}};
  scene::Light ambient;
  ambient.type = scene::Light::Type::kAmbient;
  ambient.intensity = 1.0f;
  scene::Ground no_ground;
  no_ground.enabled = false;
  const scene::Scene world(Eigen::Vector3f::Zero(), {ambient}, no_ground, objects, {camera},
                           std::nullopt);

  RendererOptions options;
  options.msaa_samples = param.msaa;
  const std::unique_ptr<Renderer> renderer = MakeRenderer(world, options);
  const std::vector<Frame> frames = renderer->Render(world.InitialState(), 0);
  ASSERT_EQ(frames.size(), 1u);
  const Image& image = *frames[0].color;
  ASSERT_EQ(image.width(), K.width());
  ASSERT_EQ(image.height(), K.height());

  // Intensity-weighted centroids in windows about OpenCV's pixels; every lit pixel must fall in
  // some window, and every window's border must be dark (the marker lies wholly inside).
  std::vector<uint8_t> claimed(static_cast<std::size_t>(K.width()) * K.height(), 0);
  double sum_squares = 0.0, max_error = 0.0;
  int open_windows = 0;
  for (Marker& m : markers) {
    const int cx = static_cast<int>(std::lround(m.expected.x()));
    const int cy = static_cast<int>(std::lround(m.expected.y()));
    ASSERT_TRUE(cx - kWindow >= 0 && cy - kWindow >= 0 && cx + kWindow < K.width() &&
                cy + kWindow < K.height())
        << "marker window leaves the image at " << m.expected.transpose();
    double sx = 0.0, sy = 0.0, border = 0.0;
    for (int y = cy - kWindow; y <= cy + kWindow; ++y) {
      for (int x = cx - kWindow; x <= cx + kWindow; ++x) {
        const uint8_t* p = image.row(y) + 3 * x;
        const double intensity = p[0] + p[1] + p[2];
        m.mass += intensity;
        sx += intensity * x;
        sy += intensity * y;
        if (std::abs(x - cx) == kWindow || std::abs(y - cy) == kWindow) border += intensity;
        claimed[static_cast<std::size_t>(y) * K.width() + x] = 1;
      }
    }
    if (border > 0.0) ++open_windows;
    m.measured = m.mass > 0.0 ? Vector2d(sx / m.mass, sy / m.mass) : Vector2d(-1e3, -1e3);
    m.error = (m.measured - m.expected).norm();
    sum_squares += m.error * m.error;
    max_error = std::max(max_error, m.error);
  }
  int stray = 0;
  for (int y = 0; y < K.height(); ++y) {
    for (int x = 0; x < K.width(); ++x) {
      const uint8_t* p = image.row(y) + 3 * x;
      if (!claimed[static_cast<std::size_t>(y) * K.width() + x] && (p[0] | p[1] | p[2]) != 0) {
        ++stray;
      }
    }
  }
  const double rms = std::sqrt(sum_squares / markers.size());
  std::cout << param.name << ": " << markers.size() << " markers, RMS error " << rms << " px, max "
            << max_error << " px (" << renderer->DeviceDescription() << ")\n";
  RecordProperty("rms_error_px", std::to_string(rms));
  RecordProperty("max_error_px", std::to_string(max_error));

  const bool ok =
      rms <= kMaxRmsErrorPx && max_error <= kMaxErrorPx && stray == 0 && open_windows == 0;
  EXPECT_LE(rms, kMaxRmsErrorPx);
  EXPECT_LE(max_error, kMaxErrorPx);
  EXPECT_EQ(stray, 0) << "lit pixels outside every marker's window";
  EXPECT_EQ(open_windows, 0) << "markers not wholly inside their centroid windows";
  if (!ok) {
    for (std::size_t i = 0; i < markers.size(); ++i) {
      const Marker& m = markers[i];
      std::cout << "  marker " << i << ": expected " << m.expected.transpose() << ", measured "
                << m.measured.transpose() << ", error " << m.error << " px, mass " << m.mass
                << "\n";
    }
    const std::filesystem::path dir = ::testing::TempDir();
    const std::filesystem::path render_path = dir / ("marker_accuracy_" + param.name + ".png");
    const std::filesystem::path errors_path =
        dir / ("marker_accuracy_" + param.name + "_errors_x100.png");
    WritePng(image.view(), render_path);
    WritePng(Annotate(image, markers).view(), errors_path);
    ADD_FAILURE() << "wrote the render to " << render_path << " and the error field (red: error "
                  << "x 100 from OpenCV's pixel, green) to " << errors_path;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cameras, MarkerAccuracyTest,
    ::testing::Values(
        Case{"1024x768", geometry::Intrinsics(1024, 768, 900.0, 870.0, 530.3, 370.8, 2.5), 0},
        Case{"641x479", geometry::Intrinsics(641, 479, 610.0, 590.0, 317.9, 242.6, -1.7), 0},
        Case{"1024x768_msaa4", geometry::Intrinsics(1024, 768, 900.0, 870.0, 530.3, 370.8, 2.5), 4},
        Case{"641x479_msaa4", geometry::Intrinsics(641, 479, 610.0, 590.0, 317.9, 242.6, -1.7), 4}),
    [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

}  // namespace
}  // namespace saccade::render
