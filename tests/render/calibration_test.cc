// The calibration proof: rendered images of a chessboard, calibrated with OpenCV, give back the
// cameras they were rendered with (DESIGN.md: "the simulator's pixels land where OpenCV says
// they must"). OpenCV is the independent reference end to end: it finds the corners
// (cv::findChessboardCorners, cv::cornerSubPix), fits the cameras (cv::calibrateCamera,
// cv::fisheye::calibrate, cv::stereoCalibrate), and the fits are compared with the truth:
// - a radial-tangential camera with a strong barrel lens (k1 = -0.3: the image corners are
//   pulled in by about 100 px);
// - a Kannala-Brandt fisheye whose image edge sees about 92 degrees off its axis (so that the
//   renderer draws it through a cube);
// - a stereo pair 0.12 m apart with a small relative rotation, each camera with its own lens.
// Each is checked twice: the detected corners against cv::projectPoints /
// cv::fisheye::projectPoints of the true corners (the renderer's pixels, no fit involved), and
// the fitted model against the true one.
//
// The board is a picture (scene::MakePicture) of 10 x 7 squares (9 x 6 inner corners) in a
// white quiet zone half a square wide, lit by an ambient light only, so that its image is the
// texture as it is: black 0, white 255. Squares are 64 texels and the quiet zone 32: down to
// the mipmap level of 2 x 2 texels a square, every square boundary lies on a texel boundary,
// so every level is point-symmetric about each corner and filtering does not move corners.
// Each view is one state of one scene: the board follows waypoints, one a view (time k: view
// k), rendered with 4x MSAA.
//
// Corner detection: cv::cornerSubPix on the raw render scatters by ~0.07 px RMS, and about as
// much (0.06 px) on an ideal image (a CPU box filter of the board, 64 samples a pixel): its
// gradient-orthogonality estimate is noisy on edges one pixel wide, sampled by one or two
// pixels each. A Gaussian pre-blur (kBlurSigmaPx, on a float copy: no re-quantisation) brings
// the scatter to ~0.02 px; it is symmetric, so it moves no corner where the edges are straight,
// and where the lens curves them (radius of curvature R) by about sigma^2 / (2 R): 0.001 px for
// the radial-tangential lenses (R >= ~2000 px), a few thousandths at the fisheye's rim.
// Measured on llvmpipe: detected against true corners 0.018 px RMS (radtan), 0.025 px (fisheye),
// 0.021 px (stereo); 0.06 px at worst.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <numbers>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "image_camera_helpers.h"
#include "saccade/core/image.h"
#include "saccade/core/image_io.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/pose.h"
#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"

namespace saccade::render {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kDeg = std::numbers::pi / 180.0;

// ---- Tolerances ---------------------------------------------------------------------------------
// Focal lengths, relative: what a careful real calibration achieves; 0.1 % of 900 px is 0.9 px
// (a scale error of 1 mm at 1 m). A K -> projection error shows as far more.
constexpr double kMaxFocalRelativeError = 1e-3;
// Principal point, relative to the image size (0.1 % of 1024 px is 1 px): it is a position in
// the image, so its error is measured against the image, not against cx itself.
constexpr double kMaxPrincipalPointRelativeError = 1e-3;
// Reprojection RMS of the fits: the corners' own scatter is ~0.02 px; a model that is not
// OpenCV's leaves residuals of tenths of a pixel.
constexpr double kMaxRmsPx = 0.1;
// Detected corners against OpenCV's projection of the true corners, no fit: RMS and worst corner
// over all views. The detector's own scatter on the rendered board is ~0.02 px RMS, 0.08 px at
// worst; a half-pixel convention, principal point or lens-map error moves corners by >= 0.1 px
// somewhere.
constexpr double kMaxCornerRmsPx = 0.05;
constexpr double kMaxCornerErrorPx = 0.2;
// The fitted lens against the true one: the largest difference of the distortion's pixel
// displacement (both through the true K) over the rays the corners cover. The coefficients
// themselves trade off against each other (k1, k2, k3 are strongly correlated) and are printed;
// their effect in pixels is what a user of the calibration sees.
constexpr double kMaxDistortionDifferencePx = 0.1;
// The coefficients themselves, absolute, in OpenCV's order: radtan k1 k2 p1 p2 k3, fisheye
// k1 k2 k3 k4. The higher radial terms are the most correlated with each other (and with the
// focal length), so their bounds are the widest; the tangential terms are well determined.
// Measured on llvmpipe, worst over the four fits: radtan k1 7.5e-4, k2 4.7e-3, p1 p2 3.4e-5,
// k3 8.7e-3; fisheye k1 1.9e-4, k2 2.5e-4, k3 1.3e-4, k4 2.2e-5; the bounds leave 2-5x.
const std::vector<double> kMaxRadTanCoefficientError = {2e-3, 1e-2, 1e-4, 1e-4, 2e-2};
const std::vector<double> kMaxFisheyeCoefficientError = {1e-3, 1e-3, 1e-3, 2e-4};
// Stereo: baseline length, relative (0.1 % of 0.12 m is 0.12 mm), and the relative rotation
// (0.01 degree shifts a disparity by 0.16 px at f = 900 px).
constexpr double kMaxBaselineRelativeError = 1e-3;
constexpr double kMaxRotationErrorRad = 0.01 * kDeg;

// ---- Corner detection ---------------------------------------------------------------------------
// Pre-blur of cv::cornerSubPix's image (see the top) and its window's half size: the window
// (19 px) stays well inside a square (>= 25 px across in every view here).
constexpr double kBlurSigmaPx = 2.0;
constexpr int kSubPixHalfWindow = 9;
constexpr double kSubPixWindowFraction = 0.35;

// ---- The board ----------------------------------------------------------------------------------
constexpr int kSquaresX = 10, kSquaresY = 7;
constexpr int kCornersX = kSquaresX - 1, kCornersY = kSquaresY - 1;
constexpr int kTexelsPerSquare = 64;
constexpr int kBorderTexels = 32;  // the white quiet zone around the squares
constexpr double kSquareM = 0.03;
constexpr int kBoardTexelsX = kSquaresX * kTexelsPerSquare + 2 * kBorderTexels;
constexpr int kBoardTexelsY = kSquaresY * kTexelsPerSquare + 2 * kBorderTexels;
constexpr double kBoardWidthM = kSquareM * kBoardTexelsX / kTexelsPerSquare;
constexpr double kBoardHeightM = kSquareM * kBoardTexelsY / kTexelsPerSquare;
const cv::Size kPatternSize(kCornersX, kCornersY);

std::shared_ptr<const scene::Texture> BoardTexture() {
  auto texture = std::make_shared<scene::Texture>();
  texture->source = "chessboard";
  texture->image = Image(kBoardTexelsX, kBoardTexelsY, PixelFormat::kRgb8);
  for (int y = 0; y < kBoardTexelsY; ++y) {
    for (int x = 0; x < kBoardTexelsX; ++x) {
      const int a = x - kBorderTexels, b = y - kBorderTexels;
      const bool in_squares =
          a >= 0 && a < kSquaresX * kTexelsPerSquare && b >= 0 && b < kSquaresY * kTexelsPerSquare;
      const bool black = in_squares && (a / kTexelsPerSquare + b / kTexelsPerSquare) % 2 == 0;
      uint8_t* pixel = texture->image.row(y) + 3 * x;
      pixel[0] = pixel[1] = pixel[2] = black ? 0 : 255;
    }
  }
  return texture;
}

// The inner corners in OpenCV's order (i = 0..8 left to right fastest, then j = 0..5 top to
// bottom, as the texture shows them) in the picture's frame O (scene.h: the plane x = 0,
// facing +x, right +y, top +z, centred on the origin).
std::vector<Vector3d> CornersInObject() {
  std::vector<Vector3d> out;
  for (int j = 0; j < kCornersY; ++j) {
    for (int i = 0; i < kCornersX; ++i) {
      out.emplace_back(0.0, (i + 1 - 0.5 * kSquaresX) * kSquareM,
                       (0.5 * kSquaresY - 1 - j) * kSquareM);
    }
  }
  return out;
}

// The same corners as OpenCV's object points: the board's own plane z = 0.
std::vector<cv::Point3f> BoardObjectPoints() {
  std::vector<cv::Point3f> out;
  for (int j = 0; j < kCornersY; ++j) {
    for (int i = 0; i < kCornersX; ++i) {
      out.emplace_back(static_cast<float>(i * kSquareM), static_cast<float>(j * kSquareM), 0.0f);
    }
  }
  return out;
}

// The outer edge of the quiet zone, sampled, in O.
std::vector<Vector3d> BoardOutline() {
  std::vector<Vector3d> out;
  constexpr int kSamples = 16;
  for (int k = 0; k < kSamples; ++k) {
    const double s = -0.5 + static_cast<double>(k) / kSamples;
    out.emplace_back(0.0, s * kBoardWidthM, 0.5 * kBoardHeightM);
    out.emplace_back(0.0, 0.5 * kBoardWidthM, -s * kBoardHeightM);
    out.emplace_back(0.0, -s * kBoardWidthM, -0.5 * kBoardHeightM);
    out.emplace_back(0.0, -0.5 * kBoardWidthM, s * kBoardHeightM);
  }
  return out;
}

// ---- Cameras and OpenCV's projection ------------------------------------------------------------
struct TestCamera {
  std::string name;
  geometry::CameraModel model;
  geometry::Pose X_WC;
};

cv::Matx33d CvMatrix(const geometry::Intrinsics& K) {
  return {K.fx(), K.skew(), K.cx(), 0.0, K.fy(), K.cy(), 0.0, 0.0, 1.0};
}

double AngleOffAxis(const Vector3d& p_C) { return std::atan2(p_C.head<2>().norm(), p_C.z()); }

// OpenCV's pixels of points in a camera frame with matrix K and distortion coefficients D:
// cv::fisheye::projectPoints for kFisheye, cv::projectPoints otherwise (the cameras here have
// no skew, which cv::projectPoints would ignore).
std::vector<cv::Point2d> OpenCvProject(geometry::DistortionModel model, const cv::Matx33d& K,
                                       const std::vector<double>& D,
                                       const std::vector<Vector3d>& p_C) {
  std::vector<cv::Point3d> object;
  for (const Vector3d& p : p_C) object.emplace_back(p.x(), p.y(), p.z());
  std::vector<cv::Point2d> out;
  if (object.empty()) return out;
  const cv::Vec3d zero(0.0, 0.0, 0.0);
  if (model == geometry::DistortionModel::kFisheye) {
    cv::fisheye::projectPoints(object, out, zero, zero, K, D);
  } else {
    cv::projectPoints(object, zero, zero, K, D, out);
  }
  return out;
}

std::vector<cv::Point2d> OpenCvProject(const geometry::CameraModel& camera,
                                       const std::vector<Vector3d>& p_C) {
  return OpenCvProject(camera.distortion().model(), CvMatrix(camera.intrinsics()),
                       camera.distortion().coefficients(), p_C);
}

// ---- Board poses --------------------------------------------------------------------------------
// Where a view puts the board: towards the pixel (fu * (width - 1), fv * (height - 1)) of the
// first camera, `distance` metres along that pixel's ray, facing the camera, then tilted by
// `tilt` about the in-plane axis at `tilt_direction` and rolled about its normal.
struct PoseRequest {
  double fu, fv, distance, tilt, tilt_direction, roll;
};

// X_CO of a board at p_C facing the camera (its normal back along the ray, its top towards the
// image's top), tilted and rolled as asked.
geometry::Pose BoardInCamera(const Vector3d& p_C, const PoseRequest& request) {
  Matrix3d R;
  R.col(0) = -p_C.normalized();
  R.col(2) = (-Vector3d::UnitY() + R.col(0).y() * R.col(0)).normalized();
  R.col(1) = R.col(2).cross(R.col(0));
  const Vector3d axis(0.0, std::cos(request.tilt_direction), std::sin(request.tilt_direction));
  const Matrix3d tilt = Matrix3d(Eigen::AngleAxisd(request.tilt, axis)) *
                        Matrix3d(Eigen::AngleAxisd(request.roll, Vector3d::UnitX()));
  return geometry::MakePose(R * tilt, p_C);
}

// Whether the whole board at X_WO, quiet zone included, projects into every camera's image at
// least `margin` pixels inside, by rays at most `max_angle` off the axis, showing its front.
bool BoardFits(const std::vector<TestCamera>& cameras, const geometry::Pose& X_WO, double margin,
               double max_angle) {
  const std::vector<Vector3d> outline = BoardOutline();
  for (const TestCamera& camera : cameras) {
    const geometry::Pose X_CO = camera.X_WC.inverse() * X_WO;
    if (X_CO.linear().col(0).dot(-X_CO.translation()) <= 0.0) return false;
    const geometry::Intrinsics& K = camera.model.intrinsics();
    for (const Vector3d& p_O : outline) {
      const Vector3d p_C = X_CO * p_O;
      if (AngleOffAxis(p_C) > max_angle) return false;
      const std::optional<Vector2d> uv = camera.model.Project(p_C);
      if (!uv || uv->x() < margin || uv->y() < margin || uv->x() > K.width() - 1 - margin ||
          uv->y() > K.height() - 1 - margin) {
        return false;
      }
    }
  }
  return true;
}

// The board pose of a request: its target pixel is pulled towards the principal point, and the
// board moved back, until the board fits (BoardFits): boards asked for at the image's edges and
// corners end up touching them.
geometry::Pose PlaceBoard(const std::vector<TestCamera>& cameras, const PoseRequest& request,
                          double margin, double max_angle) {
  const TestCamera& first = cameras.front();
  const geometry::Intrinsics& K = first.model.intrinsics();
  const Vector2d centre(K.cx(), K.cy());
  const Vector2d target(request.fu * (K.width() - 1), request.fv * (K.height() - 1));
  double distance = request.distance;
  for (int attempt = 0; attempt < 20; ++attempt, distance *= 1.1) {
    for (double pull = 0.0; pull <= 1.0; pull += 0.01) {
      const std::optional<Vector3d> ray = first.model.Unproject(target + pull * (centre - target));
      if (!ray) continue;
      const geometry::Pose X_WO = first.X_WC * BoardInCamera(distance * ray->normalized(), request);
      if (BoardFits(cameras, X_WO, margin, max_angle)) return X_WO;
    }
  }
  ADD_FAILURE() << "no board pose fits the request at (" << request.fu << ", " << request.fv << ")";
  return first.X_WC;
}

// Deterministic views: targets on a 5 x 4 grid over the image (corners and edges included), with
// tilts of 15 to 40 degrees in every direction and rolls within 20 degrees (fixed seed).
std::vector<geometry::Pose> BoardPoses(const std::vector<TestCamera>& cameras, uint32_t seed,
                                       double min_distance, double max_distance, double max_angle) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<geometry::Pose> out;
  constexpr int kColumns = 5, kRows = 4;
  constexpr double kMarginPx = 3.0;
  for (int row = 0; row < kRows; ++row) {
    for (int column = 0; column < kColumns; ++column) {
      PoseRequest r;
      r.fu = static_cast<double>(column) / (kColumns - 1);
      r.fv = static_cast<double>(row) / (kRows - 1);
      r.distance = min_distance + (max_distance - min_distance) * unit(rng);
      r.tilt = (15.0 + 25.0 * unit(rng)) * kDeg;
      r.tilt_direction = 2.0 * std::numbers::pi * unit(rng);
      r.roll = (-20.0 + 40.0 * unit(rng)) * kDeg;
      out.push_back(PlaceBoard(cameras, r, kMarginPx, max_angle));
    }
  }
  return out;
}

// ---- Rendering ----------------------------------------------------------------------------------
// Renders the board at each pose with every camera: images[view][camera].
std::vector<std::vector<std::shared_ptr<const Image>>> RenderViews(
    const std::vector<TestCamera>& cameras, const std::vector<geometry::Pose>& X_WO) {
  std::vector<scene::Motion::Waypoint> waypoints;
  for (std::size_t k = 0; k < X_WO.size(); ++k) {
    waypoints.push_back({static_cast<double>(k), X_WO[k]});
  }
  scene::Object board;
  board.name = "board";
  board.id = 1;
  board.model = scene::MakePicture(BoardTexture(), kBoardHeightM);
  board.motion = scene::Motion::Waypoints(waypoints, false);
  std::vector<scene::CameraSpec> specs;
  for (const TestCamera& camera : cameras) {
    specs.push_back(scene::CameraSpec{camera.name, camera.model, scene::CameraMount::kWorld,
                                      camera.X_WC, geometry::ClipPlanes{0.02, 20.0},
                                      scene::SensorSpec{}});
  }
  scene::Light ambient;
  ambient.type = scene::Light::Type::kAmbient;
  ambient.intensity = 1.0f;
  scene::Ground no_ground;
  no_ground.enabled = false;
  const scene::Scene world(Eigen::Vector3f(0.3f, 0.3f, 0.3f), {ambient}, no_ground, {board}, specs,
                           std::nullopt);
  RendererOptions options;
  options.msaa_samples = 4;
  const std::unique_ptr<Renderer> renderer = MakeRenderer(world, options);
  std::vector<std::vector<std::shared_ptr<const Image>>> out;
  for (std::size_t k = 0; k < X_WO.size(); ++k) {
    scene::SceneState state = world.InitialState();
    state.time = static_cast<double>(k);
    std::vector<std::shared_ptr<const Image>> images;
    for (const Frame& frame : renderer->Render(state, static_cast<int64_t>(k))) {
      images.push_back(frame.color);
    }
    out.push_back(std::move(images));
  }
  return out;
}

std::filesystem::path Save(const Image& image, const std::string& name) {
  const std::filesystem::path path = std::filesystem::path(::testing::TempDir()) / (name + ".png");
  WritePng(image.view(), path);
  return path;
}

// ---- Corners ------------------------------------------------------------------------------------
// OpenCV's corners in one image, in the order of the true corners (the detector may return
// them from either end), or empty after a failure when it finds no board.
std::vector<cv::Point2f> DetectCorners(const Image& image, const std::vector<cv::Point2d>& truth,
                                       const std::string& name) {
  const cv::Mat rgb(image.height(), image.width(), CV_8UC3, const_cast<uint8_t*>(image.data()));
  cv::Mat gray;
  cv::cvtColor(rgb, gray, cv::COLOR_RGB2GRAY);
  std::vector<cv::Point2f> corners;
  if (!cv::findChessboardCorners(gray, kPatternSize, corners,
                                 cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
    ADD_FAILURE() << name << ": cv::findChessboardCorners finds no board; wrote the image to "
                  << Save(image, name);
    return {};
  }
  // The window must stay inside the squares around a corner: at most kSubPixWindowFraction of
  // the smallest square (seen from the detector's own, pixel-accurate corners).
  double min_square = 1e9;
  for (int j = 0; j < kCornersY; ++j) {
    for (int i = 0; i < kCornersX; ++i) {
      const cv::Point2f& a = corners[j * kCornersX + i];
      if (i > 0) min_square = std::min(min_square, cv::norm(a - corners[j * kCornersX + i - 1]));
      if (j > 0) min_square = std::min(min_square, cv::norm(a - corners[(j - 1) * kCornersX + i]));
    }
  }
  const int half_window =
      std::clamp(static_cast<int>(kSubPixWindowFraction * min_square), 2, kSubPixHalfWindow);
  cv::Mat gray_float, blurred;
  gray.convertTo(gray_float, CV_32F);
  cv::GaussianBlur(gray_float, blurred, cv::Size(0, 0), kBlurSigmaPx);
  cv::cornerSubPix(blurred, corners, cv::Size(half_window, half_window), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
  const auto distance = [](const cv::Point2f& a, const cv::Point2d& b) {
    return std::hypot(a.x - b.x, a.y - b.y);
  };
  if (distance(corners.front(), truth.back()) < distance(corners.front(), truth.front())) {
    std::reverse(corners.begin(), corners.end());
  }
  return corners;
}

struct Observations {
  std::vector<std::vector<std::vector<cv::Point2f>>> image_points;  // [camera][view]
  std::vector<std::vector<std::shared_ptr<const Image>>> images;    // [view][camera]
  double corner_rms = 0.0, corner_max = 0.0;                        // detected against true, px
  double max_angle = 0.0;      // largest angle of a corner's ray off the axis
  double min_square_px = 1e9;  // smallest distance between adjacent corners
  bool complete = false;       // the board found in every image
};

// Renders the board at the poses, finds its corners in every image and compares them with
// OpenCV's projection of the true corners.
Observations Observe(const std::vector<TestCamera>& cameras,
                     const std::vector<geometry::Pose>& X_WO, const std::string& test) {
  Observations obs;
  obs.images = RenderViews(cameras, X_WO);
  obs.image_points.resize(cameras.size());
  double sum_squares = 0.0;
  int count = 0;
  obs.complete = true;
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    const TestCamera& camera = cameras[c];
    for (std::size_t k = 0; k < X_WO.size(); ++k) {
      const Image& image = *obs.images[k][c];
      const std::string name = test + "_" + camera.name + "_view" + std::to_string(k);
      EXPECT_EQ(testing_helpers::DistortionName(image.metadata()),
                geometry::ToString(camera.model.distortion().model()))
          << name << ": the frame is not rendered with the camera's lens";
      std::vector<Vector3d> p_C;
      for (const Vector3d& p_O : CornersInObject()) {
        p_C.push_back(camera.X_WC.inverse() * X_WO[k] * p_O);
        obs.max_angle = std::max(obs.max_angle, AngleOffAxis(p_C.back()));
      }
      const std::vector<cv::Point2d> truth = OpenCvProject(camera.model, p_C);
      for (int j = 0; j < kCornersY; ++j) {
        for (int i = 0; i < kCornersX; ++i) {
          const cv::Point2d& a = truth[j * kCornersX + i];
          if (i > 0)
            obs.min_square_px =
                std::min(obs.min_square_px, cv::norm(a - truth[j * kCornersX + i - 1]));
          if (j > 0)
            obs.min_square_px =
                std::min(obs.min_square_px, cv::norm(a - truth[(j - 1) * kCornersX + i]));
        }
      }
      std::vector<cv::Point2f> corners = DetectCorners(image, truth, name);
      if (corners.empty()) {
        obs.complete = false;
        continue;
      }
      double view_max = 0.0;
      for (std::size_t i = 0; i < corners.size(); ++i) {
        const double e = std::hypot(corners[i].x - truth[i].x, corners[i].y - truth[i].y);
        sum_squares += e * e;
        ++count;
        view_max = std::max(view_max, e);
      }
      obs.corner_max = std::max(obs.corner_max, view_max);
      if (view_max > kMaxCornerErrorPx) {
        ADD_FAILURE() << name << ": a detected corner is " << view_max
                      << " px from OpenCV's projection of the true corner; wrote the image to "
                      << Save(image, name);
      }
      obs.image_points[c].push_back(std::move(corners));
    }
  }
  obs.corner_rms = count > 0 ? std::sqrt(sum_squares / count) : 0.0;
  std::cout << test << ": " << X_WO.size() << " views x " << cameras.size()
            << " cameras; detected corners against OpenCV's projection of the true ones: RMS "
            << obs.corner_rms << " px, max " << obs.corner_max << " px; rays up to "
            << obs.max_angle / kDeg << " deg off the axis; squares >= " << obs.min_square_px
            << " px\n";
  EXPECT_LE(obs.corner_rms, kMaxCornerRmsPx) << test;
  return obs;
}

// ---- Fits and their comparison with the truth
// ----------------------------------------------------
std::vector<double> ToVector(const cv::Mat& m) {
  cv::Mat d;
  m.convertTo(d, CV_64F);
  return std::vector<double>(d.begin<double>(), d.end<double>());
}

cv::Matx33d ToMatx(const cv::Mat& m) {
  cv::Mat d;
  m.convertTo(d, CV_64F);
  return cv::Matx33d(d);
}

struct Fit {
  cv::Matx33d K;
  std::vector<double> D;  // OpenCV's order: radtan k1 k2 p1 p2 k3, fisheye k1 k2 k3 k4
  double rms = 0.0;
};

struct LensDifference {
  double distortion_px = 0.0;  // the distortion alone, both through the true K
  double camera_px = 0.0;      // the whole fitted camera, K and distortion
};

// Largest pixel differences between the true and the fitted camera over the pixels whose rays
// are at most `max_angle` off the axis (a 4-pixel grid): each pixel's true ray is projected by
// OpenCV with the fitted distortion and the true K (the distortion alone), and with the fitted K
// and distortion (the whole camera).
LensDifference CompareLens(const geometry::CameraModel& truth, const Fit& fit, double max_angle) {
  const geometry::Intrinsics& K = truth.intrinsics();
  std::vector<Vector3d> rays;
  constexpr int kStep = 4;
  for (int v = 0; v < K.height() + kStep - 1; v += kStep) {
    for (int u = 0; u < K.width() + kStep - 1; u += kStep) {
      const std::optional<Vector3d> ray =
          truth.Unproject(Vector2d(std::min(u, K.width() - 1), std::min(v, K.height() - 1)));
      if (ray && AngleOffAxis(*ray) <= max_angle) rays.push_back(*ray);
    }
  }
  const geometry::DistortionModel model = truth.distortion().model();
  const std::vector<cv::Point2d> exact = OpenCvProject(truth, rays);
  const std::vector<cv::Point2d> same_k = OpenCvProject(model, CvMatrix(K), fit.D, rays);
  const std::vector<cv::Point2d> fitted = OpenCvProject(model, fit.K, fit.D, rays);
  LensDifference out;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    out.distortion_px = std::max(out.distortion_px, cv::norm(same_k[i] - exact[i]));
    out.camera_px = std::max(out.camera_px, cv::norm(fitted[i] - exact[i]));
  }
  return out;
}

// Checks a fit against the true camera and prints the numbers.
void ExpectFitMatches(const std::string& name, const geometry::CameraModel& truth, const Fit& fit,
                      double max_angle) {
  const geometry::Intrinsics& K = truth.intrinsics();
  const double fx = fit.K(0, 0) / K.fx() - 1.0, fy = fit.K(1, 1) / K.fy() - 1.0;
  const double cx = fit.K(0, 2) - K.cx(), cy = fit.K(1, 2) - K.cy();
  const LensDifference lens = CompareLens(truth, fit, max_angle);
  std::cout << name << ": RMS " << fit.rms << " px; fx " << fit.K(0, 0) << " (relative error " << fx
            << "), fy " << fit.K(1, 1) << " (" << fy << "), cx " << fit.K(0, 2) << " (" << cx
            << " px, " << cx / K.width() << " of the width), cy " << fit.K(1, 2) << " (" << cy
            << " px, " << cy / K.height() << " of the height)\n"
            << "  coefficients (fitted - true):";
  const std::vector<double>& D = truth.distortion().coefficients();
  for (std::size_t i = 0; i < fit.D.size(); ++i) {
    std::cout << " " << fit.D[i] << " (" << fit.D[i] - (i < D.size() ? D[i] : 0.0) << ")";
  }
  std::cout << "\n  over rays up to " << max_angle / kDeg
            << " deg: largest difference of the distortion " << lens.distortion_px
            << " px, of the whole fitted camera " << lens.camera_px << " px\n";
  EXPECT_LE(fit.rms, kMaxRmsPx) << name;
  EXPECT_LE(std::abs(fx), kMaxFocalRelativeError) << name;
  EXPECT_LE(std::abs(fy), kMaxFocalRelativeError) << name;
  EXPECT_LE(std::abs(cx / K.width()), kMaxPrincipalPointRelativeError) << name;
  EXPECT_LE(std::abs(cy / K.height()), kMaxPrincipalPointRelativeError) << name;
  EXPECT_LE(lens.distortion_px, kMaxDistortionDifferencePx) << name;
  const std::vector<double>& bounds =
      truth.distortion().model() == geometry::DistortionModel::kFisheye
          ? kMaxFisheyeCoefficientError
          : kMaxRadTanCoefficientError;
  ASSERT_EQ(fit.D.size(), bounds.size()) << name;
  for (std::size_t i = 0; i < fit.D.size(); ++i) {
    EXPECT_LE(std::abs(fit.D[i] - (i < D.size() ? D[i] : 0.0)), bounds[i])
        << name << ": distortion coefficient " << i;
  }
}

const cv::TermCriteria kFitCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-12);

// cv::calibrateCamera with OpenCV's default 5 coefficients (k1 k2 p1 p2 k3; k4..k6 fixed at 0).
// k3 is left free: the lenses here have one, and with corners out to ~30 degrees and 1080
// corners it is well conditioned (fixing it at 0 would leave a misfit of tenths of a pixel).
Fit CalibrateRadTan(const std::vector<std::vector<cv::Point2f>>& image_points,
                    const geometry::Intrinsics& K) {
  const std::vector<std::vector<cv::Point3f>> object(image_points.size(), BoardObjectPoints());
  cv::Mat camera_matrix, distortion;
  std::vector<cv::Mat> rvecs, tvecs;
  Fit fit;
  fit.rms = cv::calibrateCamera(object, image_points, cv::Size(K.width(), K.height()),
                                camera_matrix, distortion, rvecs, tvecs, 0, kFitCriteria);
  fit.K = ToMatx(camera_matrix);
  fit.D = ToVector(distortion);
  return fit;
}

using Clock = std::chrono::steady_clock;
double Seconds(Clock::time_point from) {
  return std::chrono::duration<double>(Clock::now() - from).count();
}

// ---- The tests ----------------------------------------------------------------------------------

TEST(CalibrationTest, RadialTangentialCameraCalibratesToItsOwnModel) {
  const auto start = Clock::now();
  const geometry::CameraModel model(geometry::Intrinsics(1024, 768, 900.0, 905.0, 515.3, 380.7),
                                    geometry::Distortion::RadialTangential(
                                        std::vector<double>{-0.30, 0.10, 0.0008, -0.0012, -0.015}));
  const std::vector<TestCamera> cameras{
      {"radtan", model,
       geometry::MakePose(geometry::RotationFromRpy(-1.7, 0.1, 0.6), Vector3d(0.4, -0.2, 1.1))}};
  const std::vector<geometry::Pose> poses = BoardPoses(cameras, 7, 0.45, 0.9, 80.0 * kDeg);
  const Observations obs = Observe(cameras, poses, "radtan");
  ASSERT_TRUE(obs.complete);
  const Fit fit = CalibrateRadTan(obs.image_points[0], model.intrinsics());
  ExpectFitMatches("radtan cv::calibrateCamera", model, fit, obs.max_angle);
  std::cout << "radtan: " << Seconds(start) << " s\n";
}

TEST(CalibrationTest, FisheyeCameraCalibratesToItsOwnModel) {
  const auto start = Clock::now();
  // The image edge (512 px from the centre) sees about 92 degrees off the axis, the corners
  // about 125 degrees: the renderer draws this lens through a cube.
  const geometry::CameraModel model(
      geometry::Intrinsics(1024, 1024, 310.0, 310.8, 514.6, 509.3),
      geometry::Distortion::Fisheye(std::vector<double>{0.02, -0.005, 0.001, -0.0002}));
  const std::vector<TestCamera> cameras{
      {"fisheye", model,
       geometry::MakePose(geometry::RotationFromRpy(-1.4, -0.2, 2.1), Vector3d(-0.3, 0.5, 0.9))}};
  // Boards (quiet zone included) up to 88 degrees off the axis: their corners reach 83 degrees,
  // where cv::findChessboardCorners still finds them.
  const std::vector<geometry::Pose> poses = BoardPoses(cameras, 11, 0.18, 0.3, 88.0 * kDeg);
  const Observations obs = Observe(cameras, poses, "fisheye");
  ASSERT_TRUE(obs.complete);
  const std::vector<std::vector<cv::Point3f>> object(poses.size(), BoardObjectPoints());
  cv::Mat K, D;
  std::vector<cv::Mat> rvecs, tvecs;
  Fit fit;
  fit.rms =
      cv::fisheye::calibrate(object, obs.image_points[0], cv::Size(1024, 1024), K, D, rvecs, tvecs,
                             cv::fisheye::CALIB_RECOMPUTE_EXTRINSIC | cv::fisheye::CALIB_FIX_SKEW |
                                 cv::fisheye::CALIB_CHECK_COND,
                             kFitCriteria);
  fit.K = ToMatx(K);
  fit.D = ToVector(D);
  ExpectFitMatches("fisheye cv::fisheye::calibrate", model, fit, obs.max_angle);
  std::cout << "fisheye: " << Seconds(start) << " s\n";
}

TEST(CalibrationTest, StereoPairCalibratesToItsBaselineAndRotation) {
  const auto start = Clock::now();
  const geometry::CameraModel left_model(
      geometry::Intrinsics(1024, 768, 880.0, 884.0, 508.2, 389.9),
      geometry::Distortion::RadialTangential(
          std::vector<double>{-0.12, 0.035, 0.0004, -0.0006, -0.004}));
  const geometry::CameraModel right_model(
      geometry::Intrinsics(1024, 768, 895.0, 893.0, 521.7, 377.1),
      geometry::Distortion::RadialTangential(
          std::vector<double>{-0.10, 0.02, -0.0005, 0.0003, 0.003}));
  // The right camera 0.12 m to the left camera's right (+x), turned in by 1.5 degrees, pitched
  // by 0.4 and rolled by 0.6 degrees.
  const geometry::Pose X_WL =
      geometry::MakePose(geometry::RotationFromRpy(-1.6, 0.05, -0.4), Vector3d(0.2, 0.7, 1.2));
  const geometry::Pose X_LR =
      geometry::MakePose(Matrix3d(Eigen::AngleAxisd(-1.5 * kDeg, Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(0.4 * kDeg, Vector3d::UnitX()) *
                                  Eigen::AngleAxisd(0.6 * kDeg, Vector3d::UnitZ())),
                         Vector3d(0.12, 0.0, 0.0));
  const std::vector<TestCamera> cameras{{"left", left_model, X_WL},
                                        {"right", right_model, X_WL * X_LR}};
  const std::vector<geometry::Pose> poses = BoardPoses(cameras, 5, 0.55, 0.9, 80.0 * kDeg);
  const Observations obs = Observe(cameras, poses, "stereo");
  ASSERT_TRUE(obs.complete);
  const Fit left = CalibrateRadTan(obs.image_points[0], left_model.intrinsics());
  const Fit right = CalibrateRadTan(obs.image_points[1], right_model.intrinsics());
  ExpectFitMatches("stereo left cv::calibrateCamera", left_model, left, obs.max_angle);
  ExpectFitMatches("stereo right cv::calibrateCamera", right_model, right, obs.max_angle);

  // The rotation and translation of the left camera's frame in the right camera's (OpenCV's
  // p_R = R p_L + T), with each camera's intrinsics as calibrated alone.
  const std::vector<std::vector<cv::Point3f>> object(poses.size(), BoardObjectPoints());
  cv::Mat K1(left.K), D1(left.D), K2(right.K), D2(right.D), R, T, E, F;
  const double rms = cv::stereoCalibrate(object, obs.image_points[0], obs.image_points[1], K1, D1,
                                         K2, D2, cv::Size(1024, 768), R, T, E, F,
                                         cv::CALIB_USE_INTRINSIC_GUESS, kFitCriteria);
  std::cout << "K1 " << K1 << "\nD1 " << D1 << "\nK2 " << K2 << "\nD2 " << D2 << "\n";
  const geometry::Pose X_RL = X_LR.inverse();
  Matrix3d R_fit;
  Vector3d T_fit;
  for (int r = 0; r < 3; ++r) {
    T_fit(r) = T.at<double>(r);
    for (int c = 0; c < 3; ++c) R_fit(r, c) = R.at<double>(r, c);
  }
  const double baseline_error = T_fit.norm() / X_RL.translation().norm() - 1.0;
  const double rotation_error = Eigen::AngleAxisd(R_fit * X_RL.linear().transpose()).angle();
  const double direction_error =
      std::acos(std::clamp(T_fit.normalized().dot(X_RL.translation().normalized()), -1.0, 1.0));
  std::cout << "stereo cv::stereoCalibrate: RMS " << rms << " px; |T| " << T_fit.norm()
            << " m (relative error " << baseline_error << "), T's direction off by "
            << direction_error / kDeg << " deg, R off by " << rotation_error / kDeg << " deg\n";
  EXPECT_LE(rms, kMaxRmsPx);
  EXPECT_LE(std::abs(baseline_error), kMaxBaselineRelativeError);
  EXPECT_LE(rotation_error, kMaxRotationErrorRad);
  std::cout << "stereo: " << Seconds(start) << " s\n";
}

}  // namespace
}  // namespace saccade::render
