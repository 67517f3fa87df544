// Rendered pixels land where OpenCV projects them (DESIGN.md: "the simulator's pixels land where
// OpenCV says they must"): small smooth markers at known 3D points, seen by a world camera, and
// each marker's intensity-weighted centroid in the rendered image compared to OpenCV's. The
// cameras: pinholes with an off-centre principal point, fx != fy and skew, at an even and at an
// odd image size; a strong radial-tangential lens (barrel, k1 = -0.3: the image corners are
// pulled in by about 100 px), rendered through a wider pinhole view and remapped; and a
// Kannala-Brandt fisheye seeing 95 degrees off its axis at the image's edges (a 190 degree
// lens), rendered through a cube and remapped. cv::fisheye::projectPoints works on x/z and y/z,
// so it mirrors rays beyond 90 degrees: the fisheye's markers stay within 87.5 degrees of the
// axis (a 175 degree field; geometry/lens_map_test.cc checks the rim beyond 90 degrees against
// the Kannala-Brandt formula).
//
// OpenCV's centroid of a marker is the centroid of its image as cv::projectPoints (or
// cv::fisheye::projectPoints) maps it: every texel of the marker projected, weighted by its
// value times the area OpenCV's projection gives it (the intensity a sensor collects is the
// texture's value per unit of IMAGE area). Where the map from the marker's plane to the image is
// affine (a pinhole camera, a marker at constant depth: u = (fx X + s Y) / Z + cx,
// v = fy Y / Z + cy) that is exactly the projection of the marker's centre, which the pinhole
// cases check; through a lens the map curves and the centroid differs from the centre's pixel
// by up to a few thousandths of a pixel, which the reference includes rather than ignores.
// (A sphere would not do even for a pinhole: its image is an ellipse whose centre lies
// f tan(theta) sin^2(alpha) / cos^2(theta) beyond the projection of its centre.)
//
// Why the comparison measures the projection and nothing else:
// - Each marker is a picture (scene::MakePicture) of a Gaussian blob, smooth (sigma ~ 1.7 px on
//   screen) and point-symmetric about the texture's centre, as are all its mipmap levels: no
//   hard edges to alias, and sampling it at pixel centres moves the centroid only by the (tiny)
//   aliasing of a smooth function. Pinhole cases hold it fronto-parallel; lens cases turn it to
//   face the camera (at 95 degrees off the axis no plane of constant depth exists).
// - 8-bit quantisation adds a random +-0.5 LSB a pixel: on a blob of peak 255 and sigma 2 px
//   the centroid moves by ~0.003 px RMS, 0.008 px at most (simulated over sub-pixel phases).
// - Vertex positions go through float matrices built in double (model-view computed in double
//   on the CPU), and llvmpipe snaps vertices to 1/256 px: both far below 0.01 px.
// - The lens remap is a box filter of each pixel's footprint (render/gl/internal_effect_
//   shaders.h): symmetric, so it moves no centroid either.
// Black background, no ground, ambient light only: the image is the blobs and zeros.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <numbers>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "image_camera_helpers.h"
#include "saccade/core/image.h"
#include "saccade/core/image_io.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/distortion.h"
#include "saccade/geometry/pose.h"
#include "saccade/head/head_model.h"
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

constexpr double kDeg = std::numbers::pi / 180.0;

struct Case {
  std::string name;
  geometry::CameraModel model;
  int msaa;
  double max_angle_deg = 90.0;  // markers only where the ray is at most this far off the axis
  // A head file: the camera is instead its right eye (the model from the head, the pose from its
  // forward kinematics at home), rendered as the robot's eye camera with the body hidden.
  std::string head = {};
  // Every photometric effect on (issue 45): cos^4 vignetting, a thin lens focused at 3 m (the
  // markers lie at 1.5 to 8 m: circles of 1.5 to 2.4 px), an RGGB mosaic demosaiced, an sRGB
  // tone curve. The centroids are those of the light, the image linearised through the
  // inverse of the sRGB curve (IEC 61966-2-1): the curve's slope of 12.92 at black weighs the
  // marker's faint tails, and their 8-bit rounding, 13 times as much as its peak (measured on
  // the encoded values: RMS 0.032 px with the curve alone, against 0.017-0.018 px with any of
  // the other effects alone).
  bool photometric = false;
};

std::ostream& operator<<(std::ostream& os, const Case& c) { return os << c.name; }

struct Marker {
  Vector3d p_W;
  Vector2d expected;  // OpenCV's pixel
  Vector2d measured = Vector2d::Zero();
  double mass = 0.0;
  double error = 0.0;
};

// OpenCV's pixels of world points for a camera at X_WC: cv::fisheye::projectPoints for a
// fisheye, cv::projectPoints otherwise. cv::projectPoints reads no skew from its camera matrix,
// so without distortion it projects with an identity matrix to normalized coordinates and K
// (with skew) is applied after, as in tests/geometry/camera_model_test.cc; the lens cases have
// no skew.
std::vector<Vector2d> OpenCvProject(const geometry::CameraModel& camera, const geometry::Pose& X_WC,
                                    const std::vector<Vector3d>& points_W) {
  const geometry::Intrinsics& K = camera.intrinsics();
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
  const cv::Matx33d Kcv(K.fx(), K.skew(), K.cx(), 0.0, K.fy(), K.cy(), 0.0, 0.0, 1.0);
  const geometry::DistortionModel model = camera.distortion().model();
  const std::vector<double>& D = camera.distortion().coefficients();
  std::vector<cv::Point2d> image;
  std::vector<Vector2d> out;
  if (model == geometry::DistortionModel::kFisheye) {
    cv::fisheye::projectPoints(object, image, rvec, tvec, Kcv, D, K.skew() / K.fx());
  } else if (model == geometry::DistortionModel::kRadialTangential) {
    EXPECT_EQ(K.skew(), 0.0) << "cv::projectPoints ignores skew";
    cv::projectPoints(object, rvec, tvec, Kcv, D, image);
  } else {
    std::vector<cv::Point2d> normalized;
    cv::projectPoints(object, rvec, tvec, cv::Matx33d::eye(), cv::noArray(), normalized);
    for (const cv::Point2d& p : normalized) {
      const cv::Vec3d q = Kcv * cv::Vec3d(p.x, p.y, 1.0);
      image.emplace_back(q[0] / q[2], q[1] / q[2]);
    }
  }
  for (const cv::Point2d& p : image) out.emplace_back(p.x, p.y);
  return out;
}

// OpenCV's centroid of the image of a marker texture at X_WO (MakePicture's frame: the plane
// x = 0, right +y, top +z, `side` metres square), seen by the camera at X_WC: the texel centres
// projected, each weighted by its value times the area of its projected texel (the cross
// product of the projected steps to its neighbours' centres, by central differences).
Vector2d OpenCvCentroid(const geometry::CameraModel& camera, const geometry::Pose& X_WC,
                        const Image& texture, const geometry::Pose& X_WO, double side) {
  const int n = texture.width();
  const double texel = side / n;
  std::vector<Vector3d> points;  // per texel: centre, -y, +y, -z, +z half a texel away
  std::vector<double> values;
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const double value = texture.row(y)[3 * x];
      if (value == 0.0) continue;
      // Texel (x, y) from the top-left: right along +y, down along -z.
      const Vector3d p_O(0.0, (x + 0.5) * texel - 0.5 * side, 0.5 * side - (y + 0.5) * texel);
      for (const Vector3d& d : {Vector3d(0, 0, 0), Vector3d(0, -0.5, 0), Vector3d(0, 0.5, 0),
                                Vector3d(0, 0, -0.5), Vector3d(0, 0, 0.5)}) {
        points.push_back(X_WO * (p_O + texel * d));
      }
      values.push_back(value);
    }
  }
  const std::vector<Vector2d> uv = OpenCvProject(camera, X_WC, points);
  Vector2d sum = Vector2d::Zero();
  double mass = 0.0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const Vector2d* q = &uv[5 * i];
    const Vector2d a = q[2] - q[1], b = q[4] - q[3];
    const double weight = values[i] * std::abs(a.x() * b.y() - a.y() * b.x());
    sum += weight * q[0];
    mass += weight;
  }
  return sum / mass;
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

// An 8-bit sRGB-encoded value's linear value, 0..255 (IEC 61966-2-1's decoding).
double SrgbToLinear(uint8_t encoded) {
  const double v = encoded / 255.0;
  return 255.0 * (v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
}

class MarkerAccuracyTest : public ::testing::TestWithParam<Case> {};

TEST_P(MarkerAccuracyTest, CentroidsMatchOpenCvProjection) {
  const Case& param = GetParam();
  std::optional<head::HeadModel> head;
  if (!param.head.empty()) head.emplace(head::HeadModel::FromFile(param.head));
  const geometry::CameraModel& model = head ? head->camera(1).model : param.model;
  const geometry::Intrinsics& K = model.intrinsics();
  const bool lens = model.distortion().model() != geometry::DistortionModel::kNone;
  // A camera metres from the origin, in a general orientation; or the head's right eye.
  const geometry::Pose X_WC = head ? head->CameraPoses(head->Home())[1]
                                   : geometry::MakePose(geometry::RotationFromRpy(-1.9, 0.15, 2.4),
                                                        Vector3d(3.2, -1.7, 1.4));

  // Markers on a jittered grid that covers the whole image up to kBorderPx from its edges,
  // corners included (where there is a ray at most max_angle_deg off the axis), at depths (along
  // the ray) from 1.5 m to 8 m.
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> jitter(-0.5, 0.5), depth(1.5, 8.0);
  constexpr int kColumns = 11, kRows = 9;
  auto texture = GaussianTexture();
  std::vector<scene::Object> objects;
  std::vector<Marker> markers;
  double max_angle = 0.0;  // of the markers' centres off the axis
  for (int row = 0; row < kRows; ++row) {
    for (int column = 0; column < kColumns; ++column) {
      const double span_u = K.width() - 1 - 2 * kBorderPx, span_v = K.height() - 1 - 2 * kBorderPx;
      double u = kBorderPx + span_u * column / (kColumns - 1) + jitter(rng);
      double v = kBorderPx + span_v * row / (kRows - 1) + jitter(rng);
      u = std::clamp(u, kBorderPx, K.width() - 1 - kBorderPx);
      v = std::clamp(v, kBorderPx, K.height() - 1 - kBorderPx);
      const double distance = depth(rng);
      const std::optional<Vector3d> ray = model.Unproject(Vector2d(u, v));
      if (!ray) continue;  // beyond where the lens's polynomial is invertible (the fisheye)
      const Vector3d direction = ray->normalized();
      const double angle = std::acos(std::clamp(direction.z(), -1.0, 1.0));
      if (angle > param.max_angle_deg * kDeg) continue;
      max_angle = std::max(max_angle, angle);
      const Vector3d p_C =
          lens ? Vector3d(distance * direction) : Vector3d(distance / direction.z() * direction);
      // Pinhole: the picture faces the camera (its +x towards -z_C), upright in the image (its
      // top, +z, towards -y_C), its right edge along +x_C: fronto-parallel. Lens: its +x
      // towards the camera's centre, its top as close to -y_C as that allows.
      Eigen::Matrix3d R_CO;
      if (lens) {
        R_CO.col(0) = -direction;
        R_CO.col(2) = (-Vector3d::UnitY() + direction.y() * direction).normalized();
        R_CO.col(1) = R_CO.col(2).cross(R_CO.col(0));
      } else {
        R_CO.col(0) = -Vector3d::UnitZ();
        R_CO.col(1) = Vector3d::UnitX();
        R_CO.col(2) = -Vector3d::UnitY();
      }
      const geometry::Pose X_WO = X_WC * geometry::MakePose(R_CO, p_C);
      // About kMarkerPx pixels on screen along its larger direction: the picture's pixels per
      // metre from OpenCV's projection of its centre and points 1 mm along its axes.
      const std::vector<Vector2d> local = OpenCvProject(
          model, X_WC,
          {X_WO.translation(), X_WO * Vector3d(0.0, 1e-3, 0.0), X_WO * Vector3d(0.0, 0.0, 1e-3)});
      const double px_per_m =
          1e3 * std::max((local[1] - local[0]).norm(), (local[2] - local[0]).norm());
      const double side = kMarkerPx / px_per_m;
      scene::Object object;
      object.name = "marker" + std::to_string(markers.size());
      object.id = static_cast<uint32_t>(markers.size() + 1);
      object.model = scene::MakePicture(texture, side);
      object.motion = scene::Motion::Static(X_WO);
      objects.push_back(object);
      Marker marker{X_WO.translation(), Vector2d::Zero()};
      marker.expected = OpenCvCentroid(model, X_WC, texture->image, X_WO, side);
      markers.push_back(marker);
    }
  }
  ASSERT_GE(markers.size(), 40u) << "markers in the field of view";

  scene::CameraSpec camera{"world",
                           model,
                           scene::CameraMount::kWorld,
                           X_WC,
                           geometry::ClipPlanes{0.1, 20.0},
                           scene::SensorSpec{}};
  if (param.photometric) {
    camera.sensor.color.cfa = scene::CfaPattern::kRggb;
    camera.sensor.color.tone_curve = scene::ToneCurveKind::kSrgb;
    camera.lens.vignetting = scene::VignettingModel::kCos4;
    camera.lens.f_number = 2.0;
    camera.lens.focal_length_m = 0.016;
    camera.lens.focus_distance_m = 3.0;
  }
  scene::Light ambient;
  ambient.type = scene::Light::Type::kAmbient;
  ambient.intensity = 1.0f;
  scene::Ground no_ground;
  no_ground.enabled = false;
  std::vector<scene::CameraSpec> cameras = {camera};
  std::optional<scene::Robot> robot;
  if (head) {  // the eyes as a head file's scene has them (scene_loader.cc), the body hidden
    cameras = {};
    for (const auto& [name, eye, mount] : {std::tuple{"left", 0, scene::CameraMount::kLeftEye},
                                           std::tuple{"right", 1, scene::CameraMount::kRightEye}}) {
      cameras.push_back(scene::CameraSpec{name, head->camera(eye).model, mount,
                                          geometry::Pose::Identity(),
                                          geometry::ClipPlanes{0.1, 20.0}, scene::SensorSpec{}});
    }
    robot = scene::Robot{*head, head->Home(), false, {}, static_cast<uint32_t>(markers.size() + 1)};
  }
  const scene::Scene world(Eigen::Vector3f::Zero(), {ambient}, no_ground, objects, cameras, robot);

  RendererOptions options;
  options.msaa_samples = param.msaa;
  if (head) options.cameras = {"right"};
  const std::unique_ptr<Renderer> renderer = MakeRenderer(world, options);
  const std::vector<Frame> frames = renderer->Render(world.InitialState(), 0);
  ASSERT_EQ(frames.size(), 1u);
  const Image& image = *frames[0].color;
  ASSERT_EQ(image.width(), K.width());
  ASSERT_EQ(image.height(), K.height());
  EXPECT_EQ(testing_helpers::DistortionName(image.metadata()),
            geometry::ToString(model.distortion().model()));

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
        const double intensity = param.photometric
                                     ? SrgbToLinear(p[0]) + SrgbToLinear(p[1]) + SrgbToLinear(p[2])
                                     : p[0] + p[1] + p[2];
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
  std::cout << param.name << ": " << markers.size() << " markers up to " << max_angle / kDeg
            << " deg off the axis, RMS error " << rms << " px, max " << max_error << " px ("
            << renderer->DeviceDescription() << ")\n";
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

const geometry::Intrinsics kEven(1024, 768, 900.0, 870.0, 530.3, 370.8, 2.5);
const geometry::Intrinsics kOdd(641, 479, 610.0, 590.0, 317.9, 242.6, -1.7);
// Strong barrel, as in calibration_test.cc.
const geometry::CameraModel kRadTan(geometry::Intrinsics(1024, 768, 900.0, 905.0, 515.3, 380.7),
                                    geometry::Distortion::RadialTangential(std::vector<double>{
                                        -0.30, 0.10, 0.0008, -0.0012, -0.015}));
// theta_d = theta (1 + k1 theta^2 + ...) reaches 512 px from the centre at theta ~ 95 degrees.
const geometry::CameraModel kFisheye190(
    geometry::Intrinsics(1024, 1024, 305.0, 305.6, 512.8, 510.9),
    geometry::Distortion::Fisheye(std::vector<double>{0.01, -0.003, 0.0005, -0.0001}));

// The humanoid head's right eye: a Gazebo <sensor type="camera"> block (1024 x 768,
// horizontal_fov 0.8 rad, Gazebo's radial-tangential <distortion>) on a URDF link, placed by the
// head's forward kinematics. Its intrinsics are Gazebo's: fx = fy = width / 2 / tan(fov / 2).
const std::string kHumanoid = std::string(SACCADE_SOURCE_DIR) + "/robots/humanoid.yaml";

TEST(GazeboCamera, IntrinsicsAreGazebosFormula) {
  const head::HeadModel head = head::HeadModel::FromFile(kHumanoid);
  for (int eye = 0; eye < 2; ++eye) {
    const geometry::Intrinsics& K = head.camera(eye).model.intrinsics();
    EXPECT_EQ(K.width(), 1024);
    EXPECT_EQ(K.height(), 768);
    EXPECT_NEAR(K.fx(), 1024 / 2.0 / std::tan(0.8 / 2.0), 1e-9);
    EXPECT_NEAR(K.fy(), K.fx(), 1e-9);
  }
  EXPECT_EQ(head.camera(1).model.distortion().model(),
            geometry::DistortionModel::kRadialTangential);
}

INSTANTIATE_TEST_SUITE_P(
    Cameras, MarkerAccuracyTest,
    ::testing::Values(Case{"1024x768", geometry::CameraModel(kEven), 0},
                      Case{"641x479", geometry::CameraModel(kOdd), 0},
                      Case{"1024x768_msaa4", geometry::CameraModel(kEven), 4},
                      Case{"641x479_msaa4", geometry::CameraModel(kOdd), 4},
                      Case{"radtan_strong", kRadTan, 0}, Case{"radtan_strong_msaa4", kRadTan, 4},
                      Case{"radtan_strong_photometric", kRadTan, 0, 90.0, "", true},
                      Case{"fisheye_190deg_msaa4", kFisheye190, 4, 87.5},
                      Case{"gazebo_humanoid_right_eye_msaa4", geometry::CameraModel(kEven), 4, 90.0,
                           kHumanoid}),
    [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

}  // namespace
}  // namespace saccade::render
