// Spectral residual saliency (Hou & Zhang 2007): an object pasted into a photograph is a zone,
// the top one on a plain background; shading has no zone; bad options and images are refused
// by name. The cost per 1024 x 768 frame is bench/saliency_bench.cc's.
#include "saccade/vision/saliency.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/core/image_io.h"

namespace saccade::vision {
namespace {

// A demo photograph from assets/ (scripts/setup.sh unpacks it from python3-skimage).
Image Photo(const std::string& name) {
  const std::filesystem::path path = std::filesystem::path(SACCADE_SOURCE_DIR) / "assets" / name;
  if (!std::filesystem::exists(path)) {
    ADD_FAILURE() << path << " is missing: run scripts/setup.sh";
    return Image();
  }
  return ReadImage(path);
}

cv::Mat Wrap(Image& image) {
  return cv::Mat(image.height(), image.width(),
                 image.format() == PixelFormat::kGray8   ? CV_8UC1
                 : image.format() == PixelFormat::kRgba8 ? CV_8UC4
                                                         : CV_8UC3,
                 image.data(), image.stride());
}

// The pasted object: a 40 x 40 px checker of four 20 px squares, black and white (at the
// default 64 px working width each square is 2.5 working pixels of a 512 px photograph).
constexpr int kObjectSide = 40;
void PasteChecker(Image& image, cv::Point top_left) {
  cv::Mat mat = Wrap(image);
  const int half = kObjectSide / 2;
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      const cv::Scalar colour = (i + j) % 2 ? cv::Scalar::all(255) : cv::Scalar::all(0);
      cv::rectangle(mat, cv::Rect(top_left.x + j * half, top_left.y + i * half, half, half), colour,
                    cv::FILLED);
    }
  }
}

// Zones must be local: a zone that covers a quarter of the image localises nothing.
constexpr double kMaxZoneShareOfImage = 0.25;

// Pastes the object at `trials` random positions (fixed seed) and returns, for each, the rank
// of the first zone whose box holds the object's centre (-1: none does).
std::vector<int> RanksOfPastedObject(const std::string& photo, unsigned seed, int trials) {
  const Image original = Photo(photo);
  if (original.empty()) return {};
  const SpectralResidualSaliency saliency;  // default options: up to 5 zones
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> x_of(0, original.width() - kObjectSide);
  std::uniform_int_distribution<int> y_of(0, original.height() - kObjectSide);
  std::vector<int> ranks;
  for (int trial = 0; trial < trials; ++trial) {
    Image image = original;
    const cv::Point top_left(x_of(rng), y_of(rng));
    PasteChecker(image, top_left);
    const cv::Point centre = top_left + cv::Point(kObjectSide / 2, kObjectSide / 2);
    const std::vector<SaliencyZone> zones = saliency.Zones(image);
    int rank = -1;
    for (std::size_t i = 0; i < zones.size() && rank < 0; ++i) {
      if (zones[i].box.contains(centre)) rank = static_cast<int>(i);
    }
    if (rank >= 0) {
      EXPECT_LE(zones[rank].box.area(), kMaxZoneShareOfImage * image.width() * image.height())
          << photo << ": zone " << zones[rank].box;
    }
    std::ostringstream where;
    where << photo << ": object centre " << centre << ", zones";
    for (const SaliencyZone& zone : zones)
      where << " " << zone.box << " (peak " << zone.score << ")";
    ranks.push_back(rank);
    if (rank != 0) std::cout << where.str() << "\n";
  }
  return ranks;
}

// The cat: a photograph with one subject on a plain background. The object is always a zone,
// and the top zone unless it lands by the cat's eyes, which are salient too (1 of 16 at this
// seed: centre (307, 73), ranked third after both eyes).
constexpr int kTrials = 16;
constexpr int kMinTopInTheCat = 14;

TEST(SpectralResidualSaliency, PastedObjectIsTheTopZoneInTheCat) {
  const std::vector<int> ranks = RanksOfPastedObject("chelsea.png", 2, kTrials);
  ASSERT_EQ(ranks.size(), static_cast<std::size_t>(kTrials));
  EXPECT_EQ(std::count(ranks.begin(), ranks.end(), -1), 0)
      << "ranks " << ::testing::PrintToString(ranks);
  EXPECT_GE(std::count(ranks.begin(), ranks.end(), 0), kMinTopInTheCat)
      << "ranks " << ::testing::PrintToString(ranks);
  std::cout << "chelsea: the object is the top zone in "
            << std::count(ranks.begin(), ranks.end(), 0) << " of " << kTrials << ", ranks "
            << ::testing::PrintToString(ranks) << "\n";
}

// The astronaut: a cluttered photograph, where the helmet's bright rim on black outranks the
// object most of the time (11 of 16 at this seed); the object is still always a zone.
TEST(SpectralResidualSaliency, PastedObjectIsAZoneInTheAstronaut) {
  const std::vector<int> ranks = RanksOfPastedObject("astronaut.png", 1, kTrials);
  ASSERT_EQ(ranks.size(), static_cast<std::size_t>(kTrials));
  EXPECT_EQ(std::count(ranks.begin(), ranks.end(), -1), 0)
      << "ranks " << ::testing::PrintToString(ranks);
  std::cout << "astronaut: the object is the top zone in "
            << std::count(ranks.begin(), ranks.end(), 0) << " of " << kTrials << ", ranks "
            << ::testing::PrintToString(ranks) << "\n";
}

TEST(SpectralResidualSaliency, MapIsOfTheImageSizeInZeroToOne) {
  const Image photo = Photo("astronaut.png");
  ASSERT_FALSE(photo.empty());
  const cv::Mat map = SpectralResidualSaliency().Map(photo);
  EXPECT_EQ(map.type(), CV_32FC1);
  EXPECT_EQ(map.cols, photo.width());
  EXPECT_EQ(map.rows, photo.height());
  double lo = 0, hi = 0;
  cv::minMaxLoc(map, &lo, &hi);
  EXPECT_GE(lo, 0.0);
  EXPECT_LE(hi, 1.0);
  EXPECT_GT(hi, 0.9);  // bilinear upsampling keeps the working map's maximum (1) almost whole
}

// Gray conversion happens once, on 8-bit pixels: RGB, RGBA and their gray image give one map.
TEST(SpectralResidualSaliency, RgbRgbaAndGrayGiveTheSameMap) {
  Image rgb = Photo("chelsea.png");
  ASSERT_FALSE(rgb.empty());
  Image gray(rgb.width(), rgb.height(), PixelFormat::kGray8);
  Image rgba(rgb.width(), rgb.height(), PixelFormat::kRgba8);
  cv::Mat gray_mat = Wrap(gray), rgba_mat = Wrap(rgba);
  cv::cvtColor(Wrap(rgb), gray_mat, cv::COLOR_RGB2GRAY);
  cv::cvtColor(Wrap(rgb), rgba_mat, cv::COLOR_RGB2RGBA);
  const SpectralResidualSaliency saliency;
  const cv::Mat from_rgb = saliency.Map(rgb);
  EXPECT_EQ(cv::norm(from_rgb, saliency.Map(gray), cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(from_rgb, saliency.Map(rgba), cv::NORM_INF), 0.0);
}

// The working map is scaled so that its maximum is 1 (float arithmetic).
constexpr double kExactPeak = 1e-6;

TEST(SpectralResidualSaliency, ZonesAreRankedDisjointAndHoldTheirPeak) {
  Image photo = Photo("astronaut.png");
  ASSERT_FALSE(photo.empty());
  for (int max_zones : {1, 3, 8}) {
    SpectralResidualSaliency::Options options;
    options.max_zones = max_zones;
    const SpectralResidualSaliency saliency(options);
    const SpectralResidualSaliency::Result result = saliency.Compute(photo);
    ASSERT_FALSE(result.zones.empty());
    EXPECT_LE(static_cast<int>(result.zones.size()), max_zones);
    EXPECT_EQ(saliency.Zones(photo).size(), result.zones.size());
    EXPECT_NEAR(result.zones.front().score, 1.0, kExactPeak);
    double total_share = 0;
    const cv::Rect frame(0, 0, photo.width(), photo.height());
    for (std::size_t i = 0; i < result.zones.size(); ++i) {
      const SaliencyZone& zone = result.zones[i];
      EXPECT_GT(zone.score, 0.0);
      EXPECT_GT(zone.share, 0.0);
      if (i > 0) {
        EXPECT_LE(zone.score, result.zones[i - 1].score);
      }
      EXPECT_EQ(zone.box & frame, zone.box);
      EXPECT_TRUE(zone.box.contains(zone.peak)) << zone.box << " " << zone.peak;
      // The peak is salient: above the threshold (3 x the mean) in the full-size map.
      EXPECT_GT(result.map.at<float>(zone.peak), options.zone_threshold * cv::mean(result.map)[0]);
      for (std::size_t j = 0; j < i; ++j) {
        EXPECT_EQ((zone.box & result.zones[j].box).area(), 0)
            << zone.box << " overlaps " << result.zones[j].box;
      }
      total_share += zone.share;
    }
    EXPECT_LE(total_share, 1.0 + 1e-9);
  }
}

TEST(SpectralResidualSaliency, UniformImageHasAZeroMapAndNoZone) {
  for (int value : {0, 128, 255}) {
    Image image(320, 240, PixelFormat::kRgb8);
    Wrap(image).setTo(cv::Scalar::all(value));
    const SpectralResidualSaliency::Result result = SpectralResidualSaliency().Compute(image);
    EXPECT_EQ(cv::countNonZero(result.map), 0) << value;
    EXPECT_TRUE(result.zones.empty()) << value;
  }
}

// Shading has no salient structure (kFlatLaplacian), however the map would scale its rounding.
TEST(SpectralResidualSaliency, SmoothGradientHasAZeroMapAndNoZone) {
  Image horizontal(640, 480, PixelFormat::kGray8);
  Image vertical(640, 480, PixelFormat::kRgb8);
  Image vignette(640, 480, PixelFormat::kGray8);  // 100 levels darker in the corners
  Image diagonal(1024, 768, PixelFormat::kGray8);
  for (int y = 0; y < 480; ++y) {
    for (int x = 0; x < 640; ++x) {
      horizontal.row(y)[x] = static_cast<uint8_t>(40 + x * 160 / 640);
      const auto v = static_cast<uint8_t>(230 - y * 200 / 480);
      for (int c = 0; c < 3; ++c) vertical.row(y)[3 * x + c] = v;
      const double r2 = (x - 320.0) * (x - 320.0) + (y - 240.0) * (y - 240.0);
      vignette.row(y)[x] = static_cast<uint8_t>(200 - 100 * r2 / (400.0 * 400.0));
    }
  }
  for (int y = 0; y < 768; ++y) {
    for (int x = 0; x < 1024; ++x) {
      diagonal.row(y)[x] = static_cast<uint8_t>(20 + (x + y) * 215 / 1792);
    }
  }
  const SpectralResidualSaliency saliency;
  for (const auto& [name, image] : {std::pair{"horizontal", &horizontal},
                                    {"vertical", &vertical},
                                    {"vignette", &vignette},
                                    {"diagonal", &diagonal}}) {
    const SpectralResidualSaliency::Result result = saliency.Compute(*image);
    EXPECT_EQ(cv::countNonZero(result.map), 0) << name;
    EXPECT_TRUE(result.zones.empty())
        << name << ": " << result.zones.size() << " zones, the first " << result.zones.front().box;
  }
}

// The other side of kFlatLaplacian: a small faint square on a flat field is found.
TEST(SpectralResidualSaliency, FaintSmallSquareOnAFlatFieldIsTheTopZone) {
  Image image(640, 480, PixelFormat::kGray8);
  Wrap(image).setTo(cv::Scalar::all(128));
  const cv::Rect square(300, 200, 20, 20);
  Wrap(image)(square).setTo(cv::Scalar::all(138));
  const std::vector<SaliencyZone> zones = SpectralResidualSaliency().Zones(image);
  ASSERT_FALSE(zones.empty());
  const cv::Point centre(310, 210);
  EXPECT_TRUE(zones.front().box.contains(centre)) << zones.front().box;
  EXPECT_LE(cv::norm(zones.front().peak - centre), 10.0) << zones.front().peak;  // 1 working px
}

// What is rare is salient: a lone smooth bump on a flat field is the top zone, around it (the
// spectral residual of a bump is its contour: a ring about sigma from the centre).
TEST(SpectralResidualSaliency, LoneSmoothBumpIsTheTopZone) {
  Image image(640, 480, PixelFormat::kGray8);
  const cv::Point centre(400, 180);
  constexpr double kSigma = 40.0;
  for (int y = 0; y < 480; ++y) {
    for (int x = 0; x < 640; ++x) {
      const double r2 = (x - centre.x) * (x - centre.x) + (y - centre.y) * (y - centre.y);
      image.row(y)[x] = static_cast<uint8_t>(60 + 120 * std::exp(-r2 / (2 * kSigma * kSigma)));
    }
  }
  const std::vector<SaliencyZone> zones = SpectralResidualSaliency().Zones(image);
  ASSERT_FALSE(zones.empty());
  const cv::Rect box = zones.front().box;
  EXPECT_TRUE(box.contains(centre)) << box;
  EXPECT_TRUE(
      (box & cv::Rect(centre.x - 4 * kSigma, centre.y - 4 * kSigma, 8 * kSigma, 8 * kSigma)) == box)
      << box << " reaches more than 4 sigma from the centre";
}

// The message of the constructor's InvalidArgument, or "" when it does not throw.
std::string Refusal(const SpectralResidualSaliency::Options& options) {
  try {
    SpectralResidualSaliency saliency(options);
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "";
}

TEST(SpectralResidualSaliency, InvalidOptionsThrowNamingTheOption) {
  EXPECT_EQ(Refusal(SpectralResidualSaliency::Options()), "");
  SpectralResidualSaliency::Options options;
  options.working_width = 0;
  EXPECT_NE(Refusal(options).find("working_width 0, expected [8, 1024]"), std::string::npos)
      << Refusal(options);
  options = {};
  options.blur_sigma = -1.0;
  EXPECT_NE(Refusal(options).find("blur_sigma -1, expected [0, 64]"), std::string::npos)
      << Refusal(options);
  options = {};
  options.max_zones = 0;
  EXPECT_NE(Refusal(options).find("max_zones 0, expected [1, 1000]"), std::string::npos)
      << Refusal(options);
  options = {};
  options.zone_threshold = 0.0;
  EXPECT_NE(Refusal(options).find("zone_threshold 0, expected (0, 1000]"), std::string::npos)
      << Refusal(options);
  options = {};
  options.blur_sigma = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(Refusal(options).find("blur_sigma"), std::string::npos) << Refusal(options);
}

TEST(SpectralResidualSaliency, WrongImageFormatThrows) {
  const SpectralResidualSaliency saliency;
  for (PixelFormat format : {PixelFormat::kGray16, PixelFormat::kFloat32, PixelFormat::kUint32}) {
    const Image image(64, 48, format);
    try {
      saliency.Map(image);
      ADD_FAILURE() << "no throw for " << ToString(format);
    } catch (const InvalidArgument& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("SpectralResidualSaliency::Map"), std::string::npos) << message;
      EXPECT_NE(message.find(std::string("image format ") + ToString(format)), std::string::npos)
          << message;
      EXPECT_NE(message.find("expected rgb8, rgba8 or gray8"), std::string::npos) << message;
    }
    EXPECT_THROW(saliency.Zones(image), InvalidArgument) << ToString(format);
  }
  try {
    saliency.Zones(Image());
    ADD_FAILURE() << "no throw for an empty image";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("SpectralResidualSaliency::Zones: empty image"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace saccade::vision
