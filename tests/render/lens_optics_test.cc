// Vignetting and the thin lens's depth of field (render/lens_optics.h): cos^4 against the angle
// of the ray OpenCV's undistortPoints gives, the polynomial against its formula, and edges
// blurred by the circle of confusion of the thin-lens formula.

#include "saccade/render/lens_optics.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <string>
#include <utility>
#include <vector>

#include "render/internal_lens_optics.h"
#include "saccade/core/error.h"
#include "saccade/geometry/distortion.h"

namespace saccade::render {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

// A float factor against its double formula: float's rounding.
constexpr double kFactorTolerance = 1e-6;
// The blur's circle measured from an edge's 10-90 % width against the thin-lens formula: the
// issue's 10 %.
constexpr double kCocTolerance = 0.10;
// An edge in focus stays within this 10-90 % width (pixels): a step sampled at pixel centres
// measures 0.8 px.
constexpr double kSharpWidthPx = 1.0;

Image Uniform(int width, int height, uint8_t value) {
  Image out(width, height, PixelFormat::kRgb8);
  std::fill(out.data(), out.data() + out.size_bytes(), value);
  return out;
}

TEST(Vignetting, Cos4FollowsTheRayAngleAtTheCornersAsOpenCVUndistortsThem) {
  const geometry::Intrinsics k(160, 120, 100.0, 110.0, 70.0, 65.0);
  const std::vector<double> radtan{-0.2, 0.05, 0.001, -0.002, 0.0};  // k1 k2 p1 p2 k3
  for (const bool distorted : {false, true}) {
    const geometry::Distortion d =
        distorted ? geometry::Distortion::RadialTangential(radtan) : geometry::Distortion();
    const geometry::CameraModel camera(k, d);
    const Image factors = VignettingFactors(camera, {VignettingModel::kCos4});
    ASSERT_EQ(factors.format(), PixelFormat::kFloat32);
    const cv::Matx33d K(100, 0, 70, 0, 110, 65, 0, 0, 1);
    const std::vector<double> coefficients = distorted ? radtan : std::vector<double>{};
    for (const auto& [u, v] : {std::pair{0, 0}, std::pair{159, 0}, std::pair{0, 119},
                               std::pair{159, 119}, std::pair{70, 65}}) {
      std::vector<cv::Point2d> in{{double(u), double(v)}}, normalized;
      // Iterated to convergence (the default stops after 5 iterations, 5e-5 off at these corners).
      cv::undistortPoints(
          in, normalized, K, coefficients, cv::noArray(), cv::noArray(),
          cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-14));
      const double x = normalized[0].x, y = normalized[0].y;
      const double cos4 = std::pow(1.0 / std::sqrt(1.0 + x * x + y * y), 4);
      const float got = reinterpret_cast<const float*>(factors.row(v))[u];
      EXPECT_NEAR(got, cos4, kFactorTolerance) << u << "," << v << " distorted " << distorted;
    }
  }
  // Applied to a uniform image: the corner dims as cos^4 says, rounded.
  const geometry::CameraModel pinhole(k);
  const Image factors = VignettingFactors(pinhole, {VignettingModel::kCos4});
  Image image = Uniform(160, 120, 200);
  ApplyVignetting(image, factors);
  const double x = -70 / 100.0, y = -65 / 110.0;
  const double corner = 200.0 / std::pow(1.0 + x * x + y * y, 2);
  EXPECT_EQ(image.row(0)[0], std::lround(corner));
  EXPECT_LT(image.row(0)[0], 110);  // about 0.5 at this corner: a real fall-off
  EXPECT_EQ(image.row(65)[3 * 70], 200);
}

// The AVX2 row (8 pixels at a time) and the portable loop give the same bytes, on a width that
// leaves pixels to the loop's end, with factors above 1 (clipped at 255) and exact halves
// (125 x 0.5 = 62.5 rounds away from zero, to 63), each value the formula's rounding.
TEST(Vignetting, TheVectorRowEqualsThePortableLoopBitForBit) {
  const int width = 203, height = 7;
  Image image(width, height, PixelFormat::kRgb8);
  Image factors(width, height, PixelFormat::kFloat32);
  uint32_t state = 12345;
  const auto next = [&] { return state = state * 1664525u + 1013904223u; };
  for (int y = 0; y < height; ++y) {
    float* f = reinterpret_cast<float*>(factors.row(y));
    for (int x = 0; x < width; ++x) {
      f[x] = x % 17 == 0 ? 0.5f : static_cast<float>(next() >> 8) / (1u << 24) * 1.6f;
      for (int ch = 0; ch < 3; ++ch) image.row(y)[3 * x + ch] = static_cast<uint8_t>(next() >> 24);
    }
  }
  image.row(0)[0] = 125;  // x 0.5 = 62.5
  Image vectors = image, portable = image;
  ApplyVignetting(vectors, factors, true);
  ApplyVignetting(portable, factors, false);
  int differing = 0;
  for (int y = 0; y < height; ++y) {
    const float* f = reinterpret_cast<const float*>(factors.row(y));
    for (int i = 0; i < 3 * width; ++i) {
      differing += vectors.row(y)[i] != portable.row(y)[i];
      const double expected = std::min(255.0, static_cast<double>(image.row(y)[i] * f[i / 3]));
      ASSERT_EQ(portable.row(y)[i], std::lround(expected)) << "row " << y << " value " << i;
    }
  }
  EXPECT_EQ(differing, 0);
  EXPECT_EQ(vectors.row(0)[0], 63);
}

TEST(Vignetting, PolynomialIsOneAtThePrincipalPointAndItsSumAtTheFarthestCorner) {
  // Principal point off centre: the farthest corner is the bottom right.
  const geometry::Intrinsics k(101, 81, 90.0, 90.0, 30.0, 20.0);
  VignettingOptions options{VignettingModel::kPolynomial, {-0.3, 0.05, -0.02}};
  const Image factors = VignettingFactors(geometry::CameraModel(k), options);
  const auto at = [&](int u, int v) {
    return double{reinterpret_cast<const float*>(factors.row(v))[u]};
  };
  EXPECT_NEAR(at(30, 20), 1.0, kFactorTolerance);
  const double farthest = std::hypot(100.5 - 30.0, 80.5 - 20.0);
  for (const auto& [u, v] : {std::pair{100, 80}, std::pair{0, 0}, std::pair{60, 40}}) {
    const double r = std::hypot(u - 30.0, v - 20.0) / farthest;
    const double want = 1 - 0.3 * r * r + 0.05 * std::pow(r, 4) - 0.02 * std::pow(r, 6);
    EXPECT_NEAR(at(u, v), want, kFactorTolerance) << u << "," << v;
  }
  // r = 1 lies at the corner of the image's area, half a pixel beyond the last centre.
  EXPECT_NEAR(options.Polynomial(1.0), 1 - 0.3 + 0.05 - 0.02, 1e-12);
}

// The 10-90 % width (pixels) of the rising edge of row `y`'s first channel, crossings found by
// linear interpolation between pixel centres.
double EdgeWidth(const Image& image, int y, double low, double high) {
  const uint8_t* row = image.row(y);
  const auto crossing = [&](double level) {
    for (int x = 0; x + 1 < image.width(); ++x) {
      const double a = row[3 * x], b = row[3 * (x + 1)];
      if (a < level && b >= level) return x + (level - a) / (b - a);
    }
    return -1.0;
  };
  const double lo = low + 0.1 * (high - low), hi = low + 0.9 * (high - low);
  return crossing(hi) - crossing(lo);
}

// The 10-90 % width of a disc's edge spread function in diameters: F(t) = 1/2 + (t sqrt(1 -
// t^2) + asin t) / pi is the part of a unit disc left of x = t; the width is 2 t90 radii.
double DiscWidthPerDiameter() {
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 60; ++i) {
    const double t = 0.5 * (lo + hi);
    const double f = 0.5 + (t * std::sqrt(1 - t * t) + std::asin(t)) / M_PI;
    (f < 0.9 ? lo : hi) = t;
  }
  return lo;  // 2 t90 R / (2 R)
}

struct EdgeScene {
  Image rgb;
  Image depth;
};

// Dark (20) left of x = 47.5, bright (220) right of it, the left part at depth `left_m`, the
// right part at `right_m`.
EdgeScene Edge(int width, int height, double left_m, double right_m) {
  EdgeScene s{Image(width, height, PixelFormat::kRgb8),
              Image(width, height, PixelFormat::kFloat32)};
  for (int y = 0; y < height; ++y) {
    float* d = reinterpret_cast<float*>(s.depth.row(y));
    for (int x = 0; x < width; ++x) {
      const bool left = x < width / 2;
      std::fill(s.rgb.row(y) + 3 * x, s.rgb.row(y) + 3 * x + 3, left ? 20 : 220);
      d[x] = static_cast<float>(left ? left_m : right_m);
    }
  }
  return s;
}

// f = 16 mm at f/1, focused at 1 m, 1000 px focal length (16 um pitch): the circle is
// 16.26 |d - 1| / d pixels.
ThinLensOptions Lens() {
  ThinLensOptions lens;
  lens.focal_length_m = 0.016;
  lens.f_number = 1.0;
  lens.focus_distance_m = 1.0;
  lens.max_coc_px = 40.0;
  return lens;
}
const geometry::Intrinsics kK(96, 40, 1000.0, 1000.0, 47.5, 19.5);

TEST(DepthOfField, AnEdgeAtTheFocusDistanceStaysSharp) {
  for (const double d : {1.0, 1.001}) {
    const EdgeScene s = Edge(96, 40, d, d);
    DepthOfFieldSummary summary;
    const Image out = ApplyDepthOfField(s.rgb.view(), s.depth.view(), Lens(), kK, &summary);
    EXPECT_LT(summary.max_coc_px, 0.05) << d;
    EXPECT_LE(EdgeWidth(out, 20, 20, 220), kSharpWidthPx) << d;
    EXPECT_EQ(std::memcmp(out.data(), s.rgb.data(), out.size_bytes()), 0) << d;
  }
}

TEST(DepthOfField, AnEdgeElsewhereIsBlurredByTheThinLensCircleOfConfusion) {
  const double per_diameter = DiscWidthPerDiameter();
  EXPECT_NEAR(per_diameter, 0.6870, 1e-3);
  for (const double d : {0.5, 0.6, 0.75, 1.6, 2.5, 8.0}) {
    const EdgeScene s = Edge(96, 40, d, d);
    const ThinLensOptions lens = Lens();
    // The formula written out: A f / (s - f) |d - s| / d, over the pitch f / fx.
    const double A = 0.016 / 1.0;
    const double want_px = A * 0.016 / (1.0 - 0.016) * std::abs(d - 1.0) / d / (0.016 / 1000.0);
    EXPECT_NEAR(CircleOfConfusionPx(lens, kK, d), want_px, 1e-9);
    const Image out = ApplyDepthOfField(s.rgb.view(), s.depth.view(), lens, kK);
    const double measured = EdgeWidth(out, 20, 20, 220) / per_diameter;
    EXPECT_NEAR(measured / want_px, 1.0, kCocTolerance)
        << "depth " << d << " m: circle " << want_px << " px, measured " << measured << " px";
    RecordProperty("coc_px_at_" + std::to_string(d), std::to_string(measured / want_px));
  }
}

TEST(DepthOfField, AnInFocusForegroundNeitherBlursNorBleedsOverABlurredBackground) {
  // Foreground (left, dark) in focus, background (right, bright, 13 px circles) behind: a
  // gather by each pixel's own circle would bleed each side into the other.
  const EdgeScene s = Edge(96, 40, 1.0, 5.0);
  const Image out = ApplyDepthOfField(s.rgb.view(), s.depth.view(), Lens(), kK);
  EXPECT_EQ(std::memcmp(out.data(), s.rgb.data(), out.size_bytes()), 0);
}

TEST(DepthOfField, ABlurredForegroundSpreadsOverAnInFocusBackgroundOnBothSidesOfItsEdge) {
  // Foreground (left, dark) at 0.5 m: 16 px circles; background in focus. The edge is blurred
  // over the whole circle, half over the foreground and half over the background.
  const EdgeScene s = Edge(96, 40, 0.5, 1.0);
  const Image out = ApplyDepthOfField(s.rgb.view(), s.depth.view(), Lens(), kK);
  const double want_px = CircleOfConfusionPx(Lens(), kK, 0.5);
  const double measured = EdgeWidth(out, 20, 20, 220) / DiscWidthPerDiameter();
  EXPECT_NEAR(measured / want_px, 1.0, 0.15) << measured << " px against " << want_px;
  RecordProperty("blurred_foreground_ratio", std::to_string(measured / want_px));
  // The middle of the ramp at the edge, within a pixel.
  const uint8_t* row = out.row(20);
  EXPECT_LT(row[3 * 46], 120);
  EXPECT_GT(row[3 * 49], 120);
}

TEST(DepthOfField, TheCircleIsAnEllipseInPixelsWhenFxAndFyDiffer) {
  // fy = fx / 2: pixels twice as tall as wide (pitch f / fy down), so the circle on the sensor
  // spans half as many rows as columns. A horizontal edge (dark above row 20, bright below),
  // transposed from Edge's vertical one.
  const geometry::Intrinsics k(96, 40, 1000.0, 500.0, 47.5, 19.5);
  const double d = 0.5;
  const double across_px = CircleOfConfusionPx(Lens(), k, d);  // 16.26, in columns
  const EdgeScene s = Edge(96, 40, d, d);
  const Image out = ApplyDepthOfField(s.rgb.view(), s.depth.view(), Lens(), k);
  const double measured_across = EdgeWidth(out, 20, 20, 220) / DiscWidthPerDiameter();
  EXPECT_NEAR(measured_across / across_px, 1.0, kCocTolerance);
  Image rows(40, 96, PixelFormat::kRgb8);  // the same edge, turned: a column profile
  Image rows_depth(40, 96, PixelFormat::kFloat32);
  for (int y = 0; y < 96; ++y) {
    for (int x = 0; x < 40; ++x) {
      std::fill(rows.row(y) + 3 * x, rows.row(y) + 3 * x + 3, y < 48 ? 20 : 220);
      reinterpret_cast<float*>(rows_depth.row(y))[x] = static_cast<float>(d);
    }
  }
  const geometry::Intrinsics k_rows(40, 96, 1000.0, 500.0, 19.5, 47.5);
  const Image down = ApplyDepthOfField(rows.view(), rows_depth.view(), Lens(), k_rows);
  Image column(96, 1, PixelFormat::kRgb8);  // column 20 as a row, for EdgeWidth
  for (int y = 0; y < 96; ++y) std::copy(down.row(y) + 60, down.row(y) + 63, column.row(0) + 3 * y);
  const double measured_down = EdgeWidth(column, 0, 20, 220) / DiscWidthPerDiameter();
  EXPECT_NEAR(measured_down / (across_px / 2), 1.0, kCocTolerance)
      << measured_down << " rows against " << across_px / 2;
  RecordProperty("ellipse_across_ratio", std::to_string(measured_across / across_px));
  RecordProperty("ellipse_down_ratio", std::to_string(measured_down / (across_px / 2)));
}

TEST(DepthOfField, PixelsWithoutASurfaceAreAtInfinityAndBigCirclesAreCapped) {
  ThinLensOptions lens = Lens();
  EXPECT_NEAR(CircleOfConfusion(lens, 0.0), 0.016 * 0.016 / (1.0 - 0.016), 1e-12);
  EXPECT_NEAR(CircleOfConfusion(lens, INFINITY), CircleOfConfusion(lens, 0.0), 1e-15);
  lens.max_coc_px = 4.0;
  EdgeScene s = Edge(96, 40, 0.0, 0.0);
  DepthOfFieldSummary summary;
  const Image out = ApplyDepthOfField(s.rgb.view(), s.depth.view(), lens, kK, &summary);
  EXPECT_NEAR(summary.max_coc_px, 16.26, 0.01);
  EXPECT_EQ(summary.capped_pixels, 96 * 40);
  const double measured = EdgeWidth(out, 20, 20, 220) / DiscWidthPerDiameter();
  EXPECT_NEAR(measured, 4.0, 0.6);  // drawn at the cap
}

// The message of `f`'s InvalidArgument; fails the test when it throws none.
template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InvalidArgument";
  return "";
}

TEST(LensOptics, BadValuesAreRefusedNamingTheField) {
  ThinLensOptions lens = Lens();
  lens.f_number = 0.0;
  EXPECT_THAT(ErrorOf([&] { lens.Validate(); }),
              AllOf(HasSubstr("thin_lens.f_number"), HasSubstr("got 0")));
  lens = Lens();
  lens.focal_length_m = -0.01;
  EXPECT_THAT(ErrorOf([&] { lens.Validate(); }),
              AllOf(HasSubstr("thin_lens.focal_length_m"), HasSubstr("-0.01")));
  lens = Lens();
  lens.focus_distance_m = 0.01;  // inside the focal length
  EXPECT_THAT(ErrorOf([&] { lens.Validate(); }), AllOf(HasSubstr("thin_lens.focus_distance_m"),
                                                       HasSubstr("0.016"), HasSubstr("got 0.01")));
  lens = Lens();
  lens.pixel_pitch_m = NAN;
  EXPECT_THAT(ErrorOf([&] { lens.Validate(); }), HasSubstr("thin_lens.pixel_pitch_m"));
  lens = Lens();
  lens.max_coc_px = 0.5;
  EXPECT_THAT(ErrorOf([&] { lens.Validate(); }), HasSubstr("thin_lens.max_coc_px"));
  // Through ApplyDepthOfField too, before any pixel.
  lens = Lens();
  lens.f_number = 0.0;
  const EdgeScene s = Edge(8, 8, 1.0, 1.0);
  EXPECT_THAT(ErrorOf([&] { ApplyDepthOfField(s.rgb.view(), s.depth.view(), lens, kK); }),
              HasSubstr("thin_lens.f_number"));
  EXPECT_THAT(ErrorOf([&] { ApplyDepthOfField(s.rgb.view(), s.rgb.view(), Lens(), kK); }),
              HasSubstr("expected an rgb8 image and its float32 depth"));
  EXPECT_THAT(ErrorOf([] { ParseVignettingModel("cos3"); }),
              AllOf(HasSubstr("vignetting.model"), HasSubstr("'cos3'")));
  VignettingOptions vignetting{VignettingModel::kPolynomial, {-2.0, 0.0, 0.0}};
  EXPECT_THAT(ErrorOf([&] { vignetting.Validate(); }),
              AllOf(HasSubstr("vignetting.coefficients"), HasSubstr(">= 0")));
  vignetting.coefficients = {0.0, INFINITY, 0.0};
  EXPECT_THAT(ErrorOf([&] { vignetting.Validate(); }),
              AllOf(HasSubstr("vignetting.coefficients"), HasSubstr("a2")));
  Image small = Uniform(4, 4, 1);
  EXPECT_THAT(ErrorOf([&] { ApplyVignetting(small, Image(5, 4, PixelFormat::kFloat32)); }),
              HasSubstr("expected the same size"));
}

// The header's gather, pixel by pixel over every offset of the image (no tiles, no window, no
// vectors): what ApplyDepthOfField must equal bit for bit, the same float terms in the order of
// increasing distance.
Image DepthOfFieldByDefinition(const Image& rgb, const Image& depth, const ThinLensOptions& lens,
                               const geometry::Intrinsics& k) {
  const int w = rgb.width(), h = rgb.height();
  const auto at = [&](int x, int y) { return reinterpret_cast<const float*>(depth.row(y))[x]; };
  const auto radius = [&](float d) {
    const bool surface = std::isfinite(d) && d > 0.0f;
    return static_cast<float>(
        0.5 * std::min(CircleOfConfusionPx(lens, k, surface ? d : 0.0), lens.max_coc_px));
  };
  const auto coverage = [](float distance, float r) {
    return std::clamp(r + 0.5f - distance, 0.0f, 1.0f);
  };
  const auto area = [](float r) {
    return r < 0.5f ? r + 0.5f : static_cast<float>(M_PI) * (r * r + 1.0f / 12.0f);
  };
  struct Offset {
    int dx, dy;
    float distance;
  };
  std::vector<Offset> offsets;
  for (int dy = -h; dy <= h; ++dy) {
    for (int dx = -w; dx <= w; ++dx) {
      offsets.push_back({dx, dy, static_cast<float>(std::hypot(dx, dy * k.fx() / k.fy()))});
    }
  }
  std::stable_sort(offsets.begin(), offsets.end(),
                   [](const Offset& a, const Offset& b) { return a.distance < b.distance; });
  Image out(w, h, PixelFormat::kRgb8);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float dp = std::isfinite(at(x, y)) && at(x, y) > 0.0f
                           ? at(x, y)
                           : std::numeric_limits<float>::infinity();
      const float rp = radius(at(x, y)), nearer = dp * (1.0f - 1e-3f);
      float bw = 0.0f, fw = 0.0f, b[3] = {0, 0, 0}, f[3] = {0, 0, 0};
      for (const Offset& o : offsets) {
        const int qx = x + o.dx, qy = y + o.dy;
        if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
        const float dq = std::isfinite(at(qx, qy)) && at(qx, qy) > 0.0f
                             ? at(qx, qy)
                             : std::numeric_limits<float>::infinity();
        const uint8_t* c = rgb.row(qy) + 3 * qx;
        if (dq < nearer) {
          const float wq = coverage(o.distance, radius(at(qx, qy))) / area(radius(at(qx, qy)));
          fw += wq;
          for (int ch = 0; ch < 3; ++ch) f[ch] += wq * c[ch];
        } else {
          const float cov = coverage(o.distance, rp);
          bw += cov;
          for (int ch = 0; ch < 3; ++ch) b[ch] += cov * c[ch];
        }
      }
      for (int ch = 0; ch < 3; ++ch) {
        float value = bw > 0.0f ? b[ch] / bw : 0.0f;
        if (fw > 0.0f)
          value = std::min(1.0f, fw) * f[ch] / fw + (1.0f - std::min(1.0f, fw)) * value;
        out.row(y)[3 * x + ch] = static_cast<uint8_t>(std::lround(std::clamp(value, 0.0f, 255.0f)));
      }
    }
  }
  return out;
}

// Tiles, a window cut at each tile's reach, eight pixels at a time (four without AVX2), two
// threads, padding for the image's edges: none of it changes a value. Widths that are not
// multiples of eight (each leaving a different number of pixels to a row's scalar end), a
// height that two threads split and ones that they do not, depths from 0.4 m to 6 m and holes
// (no surface) scattered by a hash, circles up to the cap or wider than the image. The summary
// is CircleOfConfusionPx's.
TEST(DepthOfField, EqualsTheGatherPixelByPixelBitForBit) {
  struct Case {
    int w, h;
    double max_coc_px;
    bool some_capped;
  };
  // The last: circles wider than the image is tall (its padding and its window cut at the
  // image's size; without the cut the gather reads past the planes and differs).
  for (const auto& [w, h, max_coc, some_capped] :
       {Case{45, 37, 9.0, true}, Case{46, 20, 9.0, true}, Case{12, 5, 40.0, false}}) {
    Image rgb(w, h, PixelFormat::kRgb8);
    Image depth(w, h, PixelFormat::kFloat32);
    uint32_t state = 12345;
    const auto next = [&] { return state = state * 1664525u + 1013904223u; };
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        for (int ch = 0; ch < 3; ++ch) rgb.row(y)[3 * x + ch] = static_cast<uint8_t>(next() >> 24);
        const uint32_t r = next() >> 8;
        reinterpret_cast<float*>(depth.row(y))[x] =
            r % 17 == 0 ? 0.0f : static_cast<float>((x < w / 2 ? 0.4 : 1.0) + (r % 5000) * 1e-3);
      }
    }
    ThinLensOptions lens = Lens();
    lens.max_coc_px = max_coc;
    const geometry::Intrinsics k(w, h, 1000.0, 900.0, 22.0, 10.0);
    double max_coc_px = 0.0;
    int64_t capped = 0;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const float d = reinterpret_cast<const float*>(depth.row(y))[x];
        const double coc = CircleOfConfusionPx(lens, k, d > 0.0f ? d : 0.0);
        max_coc_px = std::max(max_coc_px, coc);
        capped += coc > lens.max_coc_px;
      }
    }
    EXPECT_EQ(capped > 0, some_capped) << w << " x " << h;
    const Image reference = DepthOfFieldByDefinition(rgb, depth, lens, k);
    // Every kernel this CPU has: 16 lanes (AVX-512), 8 (AVX2), 4 (portable).
    for (const int lanes : {16, 8, 4}) {
      if (DepthOfFieldLanes(lanes) != lanes) continue;
      DepthOfFieldSummary summary;
      const Image fast = ApplyDepthOfField(rgb.view(), depth.view(), lens, k, &summary, lanes);
      int differing = 0;
      for (int y = 0; y < h; ++y) {
        for (int i = 0; i < 3 * w; ++i) differing += fast.row(y)[i] != reference.row(y)[i];
      }
      EXPECT_EQ(differing, 0) << w << " x " << h << ", lanes " << lanes;
      EXPECT_EQ(summary.max_coc_px, max_coc_px) << w << " x " << h << ", lanes " << lanes;
      EXPECT_EQ(summary.capped_pixels, capped) << w << " x " << h << ", lanes " << lanes;
      // The mosaic's gather (one channel a pixel): the reference's mosaic, byte for byte.
      for (const CfaPattern pattern :
           {CfaPattern::kRggb, CfaPattern::kBggr, CfaPattern::kGrbg, CfaPattern::kGbrg}) {
        DepthOfFieldSummary mosaic_summary;
        const Image mosaic =
            ApplyDepthOfField(rgb.view(), depth.view(), lens, k, &mosaic_summary, lanes, pattern);
        const Image expected = Mosaic(reference.view(), pattern);
        ASSERT_EQ(mosaic.format(), BayerFormat(pattern, 8));
        int differing_sites = 0;
        for (int y = 0; y < h; ++y) {
          for (int x = 0; x < w; ++x) differing_sites += mosaic.row(y)[x] != expected.row(y)[x];
        }
        EXPECT_EQ(differing_sites, 0)
            << w << " x " << h << ", lanes " << lanes << ", " << ToString(pattern);
        EXPECT_EQ(mosaic_summary.max_coc_px, max_coc_px);
      }
    }
  }
  // The public function, the widest kernel.
  EXPECT_THAT(ErrorOf([] {
                Image rgb(4, 4, PixelFormat::kRgb8), depth(4, 4, PixelFormat::kFloat32);
                ApplyDepthOfFieldToMosaic(rgb.view(), depth.view(), Lens(),
                                          geometry::Intrinsics(4, 4, 100.0, 100.0, 2.0, 2.0),
                                          CfaPattern::kNone);
              }),
              HasSubstr("pattern none"));
}

// A cap far above any image (valid: finite, >= 1) and surfaces a few microns away: circles of
// millions of pixels, which pad and window no farther than the image's size (neither runs
// for hours nor overflows), and the whole image averaged: still the gather's bits.
TEST(DepthOfField, CirclesFarWiderThanTheImageCostNoMoreThanIt) {
  const int w = 12, h = 5;
  Image rgb(w, h, PixelFormat::kRgb8);
  Image depth(w, h, PixelFormat::kFloat32);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int ch = 0; ch < 3; ++ch) rgb.row(y)[3 * x + ch] = static_cast<uint8_t>(20 * x + ch);
      reinterpret_cast<float*>(depth.row(y))[x] = 1e-5f * static_cast<float>(1 + (x + y) % 3);
    }
  }
  ThinLensOptions lens = Lens();
  lens.max_coc_px = 1e30;
  const geometry::Intrinsics k(w, h, 1000.0, 900.0, 5.5, 2.0);
  DepthOfFieldSummary summary;
  const Image fast = ApplyDepthOfField(rgb.view(), depth.view(), lens, k, &summary);
  EXPECT_GT(summary.max_coc_px, 1e6);
  const Image reference = DepthOfFieldByDefinition(rgb, depth, lens, k);
  int differing = 0;
  for (int y = 0; y < h; ++y) {
    for (int i = 0; i < 3 * w; ++i) differing += fast.row(y)[i] != reference.row(y)[i];
  }
  EXPECT_EQ(differing, 0);
}

}  // namespace
}  // namespace saccade::render
