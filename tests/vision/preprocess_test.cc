// Pre-processing (seed Fig. 2): undistortion of a rendered strong radial-tangential lens, the
// median filter on salt-and-pepper noise, unsharp-mask sharpening of a step edge.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "image_camera_helpers.h"
#include "saccade/core/error.h"
#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"
#include "saccade/vision/image_camera.h"
#include "saccade/vision/median_filter.h"
#include "saccade/vision/sharpener.h"
#include "saccade/vision/undistorter.h"

namespace saccade::vision {
namespace {

// A 640 x 480 world camera with a strong barrel lens (k1 = -0.3: the outer markers move ~38 px)
// looking along +x from (0, 0, 1) at small white spheres on black, placed where the PINHOLE of
// K puts them on a 5 x 5 grid of pixels.
constexpr double kF = 500.0, kCx = 319.5, kCy = 239.5, kDepth = 3.0, kRadius = 0.02;
const std::vector<double> kDistortion = {-0.3, 0.1, 0.001, -0.0015, 0.0};

// cv::undistortPoints' default 5 iterations leave ~0.03 px at this lens's corners: iterate to
// convergence.
const cv::TermCriteria kConverged(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-12);

std::vector<cv::Point2d> GridPixels() {
  std::vector<cv::Point2d> out;
  for (double v : {50.0, 145.0, 240.0, 335.0, 430.0}) {
    for (double u : {50.0, 185.0, 320.0, 455.0, 590.0}) out.emplace_back(u, v);
  }
  return out;
}

std::string MarkerScene() {
  std::ostringstream yaml;
  yaml << "background: [0, 0, 0]\nlights:\n  - {type: ambient, intensity: 1}\n"
       << "ground: {enabled: false}\nobjects:\n";
  int i = 0;
  for (const cv::Point2d& uv : GridPixels()) {
    // p_C = depth * ((u - cx) / f, (v - cy) / f, 1); optical frame looking along +x with z up:
    // p_W = (Z, -X, 1 - Y).
    const double X = kDepth * (uv.x - kCx) / kF, Y = kDepth * (uv.y - kCy) / kF;
    yaml << "  - {name: m" << i++ << ", kind: sphere, radius: " << kRadius
         << ", color: [1, 1, 1], pose: {position: [" << kDepth << ", " << -X << ", " << 1.0 - Y
         << "]}}\n";
  }
  yaml << "cameras:\n  - name: lens\n    calibration: {width: 640, height: 480, fx: " << kF
       << ", fy: " << kF << ", cx: " << kCx << ", cy: " << kCy
       << ", distortion: {model: radtan, coefficients: [";
  for (std::size_t k = 0; k < kDistortion.size(); ++k) yaml << (k ? ", " : "") << kDistortion[k];
  yaml << "]}}\n    look_at: {eye: [0, 0, 1], target: [1, 0, 1]}\n";
  return yaml.str();
}

// Intensity-weighted centroids of the bright blobs, sorted by row then column band.
std::vector<cv::Point2d> Centroids(const Image& image) {
  cv::Mat rgb(image.height(), image.width(), CV_8UC3, const_cast<uint8_t*>(image.data()));
  cv::Mat gray, mask, labels;
  cv::cvtColor(rgb, gray, cv::COLOR_RGB2GRAY);
  cv::threshold(gray, mask, 10, 255, cv::THRESH_BINARY);
  const int n = cv::connectedComponents(mask, labels);
  std::vector<cv::Point3d> sums(n);
  for (int y = 0; y < gray.rows; ++y) {
    for (int x = 0; x < gray.cols; ++x) {
      const int l = labels.at<int>(y, x);
      if (l == 0) continue;
      const double w = gray.at<uint8_t>(y, x);
      sums[l] += cv::Point3d(w * x, w * y, w);
    }
  }
  std::vector<cv::Point2d> out;
  for (int l = 1; l < n; ++l) out.emplace_back(sums[l].x / sums[l].z, sums[l].y / sums[l].z);
  return out;
}

cv::Point2d Nearest(const std::vector<cv::Point2d>& points, const cv::Point2d& p) {
  cv::Point2d best(1e9, 1e9);
  for (const cv::Point2d& q : points) {
    if (cv::norm(q - p) < cv::norm(best - p)) best = q;
  }
  return best;
}

// Undistorted markers must land where the pinhole of K puts them. The renderer puts pixels
// within 0.05 px of OpenCV's projection (tests/render/marker_accuracy_test.cc); a ~7 px disk
// antialiased with 8 samples a pixel, resampled bilinearly and thresholded at 8 bits, has its
// centroid within ~0.1 px (measured: 0.09 px in the distorted render, 0.095 px after
// undistortion); a sphere's image centre differs from its centre's projection by
// f tan(t) sin^2(a) / cos^2(t) < 0.02 px here. 0.25 px is above all that and far below a
// wrong coefficient order or a missing distortion term (pixels to tens of pixels).
constexpr double kMaxUndistortErrorPx = 0.25;

TEST(Undistorter, RenderedLensMarkersLandWhereThePinholePutsThem) {
  const scene::Scene world = scene::Scene::FromYamlString(MarkerScene(), "markers.yaml", ".");
  render::RendererOptions options;
  options.draw_robot = false;
  options.msaa_samples = 8;  // hard-edged disks: antialiased, their centroids are not aliased
  const std::vector<render::Frame> frames =
      render::MakeRenderer(world, options)->Render(world.InitialState(), 0);
  const Image& distorted = *frames.at(0).color;
  ASSERT_EQ(testing_helpers::DistortionName(distorted.metadata()), "radtan");
  const geometry::CameraModel camera = CameraModelOf(distorted);
  const Undistorter undistorter(camera);
  const Image undistorted = undistorter.Apply(distorted);
  EXPECT_EQ(testing_helpers::DistortionName(undistorted.metadata()), "none");
  EXPECT_TRUE(testing_helpers::Coefficients(undistorted.metadata()).empty());
  EXPECT_EQ(geometry::FindCameraModel(undistorted.metadata())->intrinsics(),
            geometry::FindCameraModel(distorted.metadata())->intrinsics());
  EXPECT_EQ(undistorted.metadata().camera, distorted.metadata().camera);

  const std::vector<cv::Point2d> before = Centroids(distorted), after = Centroids(undistorted);
  ASSERT_EQ(before.size(), GridPixels().size());
  ASSERT_EQ(after.size(), GridPixels().size());
  const cv::Matx33d K(kF, 0, kCx, 0, kF, kCy, 0, 0, 1);
  double max_error = 0.0, max_shift = 0.0, max_render_error = 0.0;
  for (const cv::Point2d& pinhole : GridPixels()) {
    // Where the lens put the marker (cv::projectPoints of its pinhole pixel) ...
    std::vector<cv::Point3d> ray = {{(pinhole.x - kCx) / kF, (pinhole.y - kCy) / kF, 1.0}};
    std::vector<cv::Point2d> lens;
    cv::projectPoints(ray, cv::Vec3d(), cv::Vec3d(), K, kDistortion, lens);
    const cv::Point2d seen = Nearest(before, lens[0]);
    ASSERT_LT(cv::norm(seen - lens[0]), 0.5) << "the render put a marker off OpenCV's pixel";
    // ... and where it is after undistortion: the pinhole pixel, which is also what
    // cv::undistortPoints(P = K) makes of the distorted centroid.
    const cv::Point2d got = Nearest(after, pinhole);
    std::vector<cv::Point2d> reference;
    cv::undistortPoints(std::vector<cv::Point2d>{seen}, reference, K, kDistortion, cv::noArray(), K,
                        kConverged);
    EXPECT_LT(cv::norm(got - pinhole), kMaxUndistortErrorPx) << pinhole << " got " << got;
    EXPECT_LT(cv::norm(got - reference[0]), kMaxUndistortErrorPx) << pinhole << " got " << got;
    max_error = std::max(max_error, cv::norm(got - pinhole));
    max_shift = std::max(max_shift, cv::norm(seen - pinhole));
    max_render_error = std::max(max_render_error, cv::norm(seen - lens[0]));
  }
  std::cout << "lens moved markers by up to " << max_shift << " px; rendered within "
            << max_render_error << " px of cv::projectPoints; after undistortion the largest "
            << "error is " << max_error << " px\n";
  EXPECT_GT(max_shift, 30.0);  // the lens is strong: the test would see a missing undistortion
}

TEST(Undistorter, MapsAgreeWithUndistortPoints) {
  const geometry::CameraModel camera(geometry::Intrinsics(640, 480, kF, kF, kCx, kCy),
                                     geometry::Distortion::RadialTangential(kDistortion));
  const Undistorter undistorter(camera);
  const cv::Matx33d K(kF, 0, kCx, 0, kF, kCy, 0, 0, 1);
  for (int v = 0; v < 480; v += 37) {
    for (int u = 0; u < 640; u += 41) {
      std::vector<cv::Point2d> back;
      const cv::Point2f src = undistorter.SourceOf(u, v);
      cv::undistortPoints(std::vector<cv::Point2d>{cv::Point2d(src.x, src.y)}, back, K, kDistortion,
                          cv::noArray(), K, kConverged);
      // The maps are float: ~1e-4 px at these coordinates.
      EXPECT_NEAR(back[0].x, u, 2e-3);
      EXPECT_NEAR(back[0].y, v, 2e-3);
    }
  }
}

TEST(Undistorter, FisheyeMapsAgreeWithTheFisheyeModel) {
  const std::vector<double> k = {0.05, -0.01, 0.002, -0.0005};
  const geometry::CameraModel camera(geometry::Intrinsics(640, 480, 300, 300, kCx, kCy),
                                     geometry::Distortion::Fisheye(k));
  const Undistorter undistorter(camera);
  for (int v = 40; v < 480; v += 100) {
    for (int u = 40; u < 640; u += 100) {
      const Eigen::Vector2d expected = camera.DistortPixel(Eigen::Vector2d(u, v));
      const cv::Point2f got = undistorter.SourceOf(u, v);
      EXPECT_NEAR(got.x, expected.x(), 2e-3);
      EXPECT_NEAR(got.y, expected.y(), 2e-3);
    }
  }
}

TEST(Undistorter, ImageOfAnotherSizeIsRefused) {
  const geometry::CameraModel camera(geometry::Intrinsics(64, 48, 50, 50, 31.5, 23.5));
  const Undistorter undistorter(camera);
  try {
    undistorter.Apply(Image(32, 48, PixelFormat::kRgb8));
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_STREQ(e.what(), "Undistorter::Apply: image of 32 x 48, expected the camera's 64 x 48");
  }
  Undistorter::Options o;
  o.border_value = 300;
  EXPECT_THROW(Undistorter(camera, o), InvalidArgument);
}

// A horizontal ramp (1 DN a pixel) with 5 % of its pixels set to 0 or 255.
Image NoisyRamp(Image* clean) {
  *clean = Image(120, 80, PixelFormat::kRgb8);
  clean->metadata().camera = "left";
  clean->metadata().frame_index = 7;
  for (int y = 0; y < 80; ++y) {
    for (int x = 0; x < 120; ++x) {
      for (int c = 0; c < 3; ++c) clean->row(y)[3 * x + c] = static_cast<uint8_t>(60 + x + 10 * c);
    }
  }
  Image noisy = *clean;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int y = 0; y < 80; ++y) {
    for (int x = 0; x < 120; ++x) {
      if (uniform(rng) < 0.05) {
        const uint8_t value = uniform(rng) < 0.5 ? 0 : 255;
        for (int c = 0; c < 3; ++c) noisy.row(y)[3 * x + c] = value;
      }
    }
  }
  return noisy;
}

double MeanAbsDifference(const Image& a, const Image& b, int* large) {
  double sum = 0.0;
  *large = 0;
  for (std::size_t i = 0; i < a.size_bytes(); ++i) {
    const int d = std::abs(a.data()[i] - b.data()[i]);
    sum += d;
    if (d > 2) ++*large;
  }
  return sum / static_cast<double>(a.size_bytes());
}

TEST(MedianFilter, RemovesSaltAndPepperNoise) {
  Image clean;
  const Image noisy = NoisyRamp(&clean);
  int large_before = 0, large_after = 0;
  const double before = MeanAbsDifference(noisy, clean, &large_before);
  const Image filtered = MedianFilter().Apply(noisy);
  const double after = MeanAbsDifference(filtered, clean, &large_after);
  std::cout << "mean |error| " << before << " DN with noise, " << after << " DN filtered; "
            << large_before << " -> " << large_after << " values off by > 2 DN\n";
  EXPECT_GT(before, 5.0);
  // On a 1 DN/px ramp the 3 x 3 median of a window with a few outliers is within 1 .. 2 DN of
  // the centre; only windows with 5 or more outliers out of 9 (~1e-5 at 5 %) keep an impulse.
  EXPECT_LT(after, 0.5);
  EXPECT_EQ(large_after, 0);
  EXPECT_EQ(filtered.metadata().camera, "left");
  EXPECT_EQ(filtered.metadata().frame_index, 7);
}

TEST(MedianFilter, BadKernelSizesSayWhatIsExpected) {
  for (int size : {0, 1, 4, 257}) {
    const std::string expected = size == 4 ? "an odd number" : "[3, 255]";
    MedianFilter::Options o;
    o.kernel_size = size;
    try {
      MedianFilter f(o);
      FAIL() << size;
    } catch (const InvalidArgument& e) {
      EXPECT_EQ(std::string(e.what()), "MedianFilter::Options: kernel_size " +
                                           std::to_string(size) + ", expected " + expected);
    }
  }
}

// A vertical step edge 80 | 140 (gray). Unsharp masking adds amount * (in - blur): across the
// edge the two pixels next to it differ by 60 before and by 60 (1 + amount (1 - w0)) after,
// w0 the centre weight of the 1-D Gaussian (blur(x0) - blur(x0 - 1) = 60 w0). Far from the
// edge nothing changes.
TEST(Sharpener, IncreasesAnEdgesContrastByTheAmount) {
  Image step(64, 16, PixelFormat::kGray8);
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 64; ++x) step.row(y)[x] = x < 32 ? 80 : 140;
  }
  constexpr double kSigma = 2.0;
  double sum = 0.0;
  for (int k = -6; k <= 6; ++k) sum += std::exp(-k * k / (2 * kSigma * kSigma));
  const double w0 = 1.0 / sum;
  for (double amount : {0.0, 0.5, 1.5}) {
    Sharpener::Options o;
    o.amount = amount;
    o.sigma = kSigma;
    const Image out = Sharpener(o).Apply(step);
    const double contrast = out.row(8)[32] - out.row(8)[31];
    const double expected = 60.0 * (1.0 + amount * (1.0 - w0));
    EXPECT_NEAR(contrast, expected, 1.0) << "amount " << amount;  // two roundings
    EXPECT_EQ(out.row(8)[2], 80) << "amount " << amount;
    EXPECT_EQ(out.row(8)[61], 140) << "amount " << amount;
  }
}

TEST(Sharpener, BadOptionsSayWhatIsWrong) {
  Sharpener::Options o;
  o.amount = -1.0;
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_EQ(error, "Sharpener::Options: amount -1, expected [0, 100]");
  o = {};
  o.sigma = 0.0;
  try {
    Sharpener s(o);
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_STREQ(e.what(), "Sharpener::Options: sigma 0, expected (0, 50]");
  }
  EXPECT_THROW(Sharpener().Apply(Image(8, 8, PixelFormat::kUint32)), InvalidArgument);
}

}  // namespace
}  // namespace saccade::vision
