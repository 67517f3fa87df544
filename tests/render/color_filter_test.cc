// The colour filter array, demosaicing, white balance and tone curves (render/color_filter.h):
// OpenCV's cv::demosaicing is the reference of the demosaiced images, the formulas of the
// tone curves theirs.

#include "saccade/render/color_filter.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "saccade/core/error.h"

namespace saccade::render {
namespace {

const CfaPattern kPatterns[] = {CfaPattern::kRggb, CfaPattern::kBggr, CfaPattern::kGrbg,
                                CfaPattern::kGbrg};

// OpenCV's codes, by the pattern's cell at (0, 0) (the header's table, written out again here
// from OpenCV's documentation of the codes, not from the code under test).
int CvCode(CfaPattern pattern, DemosaicMethod method) {
  const bool ea = method == DemosaicMethod::kEdgeAware;
  switch (pattern) {
    case CfaPattern::kRggb:
      return ea ? cv::COLOR_BayerBG2RGB_EA : cv::COLOR_BayerBG2RGB;
    case CfaPattern::kBggr:
      return ea ? cv::COLOR_BayerRG2RGB_EA : cv::COLOR_BayerRG2RGB;
    case CfaPattern::kGrbg:
      return ea ? cv::COLOR_BayerGB2RGB_EA : cv::COLOR_BayerGB2RGB;
    case CfaPattern::kGbrg:
      return ea ? cv::COLOR_BayerGR2RGB_EA : cv::COLOR_BayerGR2RGB;
    case CfaPattern::kNone:
      break;
  }
  return -1;
}

cv::Mat MatOf(const Image& image) {
  const int type = BytesPerPixel(image.format()) == 3 ? CV_8UC3 : CV_8UC1;
  return cv::Mat(image.height(), image.width(), type, const_cast<uint8_t*>(image.data()),
                 image.stride());
}

Image ImageOf(const cv::Mat& rgb) {
  Image out(rgb.cols, rgb.rows, PixelFormat::kRgb8);
  rgb.copyTo(MatOf(out));
  return out;
}

// A rendered-like image: the cat from python3-skimage's data (a photograph, so textures and
// edges), cut to an odd size so that the last column and row are not a whole cell.
Image Cat() {
  cv::Mat bgr = cv::imread(std::string(SACCADE_SOURCE_DIR) + "/assets/chelsea.png");
  EXPECT_FALSE(bgr.empty()) << "assets/chelsea.png";
  if (bgr.empty()) return Image(33, 21, PixelFormat::kRgb8);
  cv::Mat rgb;
  cv::cvtColor(bgr(cv::Rect(40, 20, 161, 97)), rgb, cv::COLOR_BGR2RGB);
  return ImageOf(rgb);
}

// Noise, saturated and dark pixels, and a hard-edged block: every rounding path.
Image Noise(int width, int height, uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<int> value(0, 255);
  Image out(width, height, PixelFormat::kRgb8);
  for (std::size_t i = 0; i < out.size_bytes(); ++i) {
    const int v = value(random);
    out.data()[i] = static_cast<uint8_t>(v < 30 ? 0 : (v > 225 ? 255 : v));
  }
  return out;
}

// Demosaic against cv::demosaicing, every pixel and channel; returns the pixels that differ.
int CountDifferences(const Image& rgb, CfaPattern pattern, DemosaicMethod method) {
  const Image mosaic = Mosaic(rgb.view(), pattern);
  const Image ours = Demosaic(mosaic.view(), method);
  cv::Mat reference;
  cv::demosaicing(MatOf(mosaic), reference, CvCode(pattern, method), 3);
  EXPECT_EQ(reference.type(), CV_8UC3);
  int differ = 0;
  for (int y = 0; y < rgb.height(); ++y) {
    for (int x = 0; x < rgb.width(); ++x) {
      const cv::Vec3b want = reference.at<cv::Vec3b>(y, x);
      const uint8_t* got = ours.row(y) + 3 * x;
      if (got[0] != want[0] || got[1] != want[1] || got[2] != want[2]) {
        if (differ++ < 5) {
          ADD_FAILURE() << ToString(pattern) << " " << ToString(method) << " at (" << x << ", " << y
                        << ") of " << rgb.width() << " x " << rgb.height() << ": got "
                        << int{got[0]} << " " << int{got[1]} << " " << int{got[2]} << ", OpenCV "
                        << int{want[0]} << " " << int{want[1]} << " " << int{want[2]};
        }
      }
    }
  }
  return differ;
}

TEST(ColorFilter, PatternsSampleTheColourTheirNameSaysAtEachCellPosition) {
  // The ROS names, read row by row from (0, 0).
  EXPECT_EQ(CfaChannel(CfaPattern::kRggb, 0, 0), 0);
  EXPECT_EQ(CfaChannel(CfaPattern::kRggb, 1, 0), 1);
  EXPECT_EQ(CfaChannel(CfaPattern::kRggb, 0, 1), 1);
  EXPECT_EQ(CfaChannel(CfaPattern::kRggb, 1, 1), 2);
  EXPECT_EQ(CfaChannel(CfaPattern::kGbrg, 1, 0), 2);
  EXPECT_EQ(CfaChannel(CfaPattern::kGbrg, 0, 1), 0);
  EXPECT_EQ(CfaChannel(CfaPattern::kGrbg, 1, 0), 0);
  EXPECT_EQ(CfaChannel(CfaPattern::kBggr, 2, 2), 2);
  EXPECT_EQ(CfaChannel(CfaPattern::kBggr, 3, 3), 0);
  // A 2 x 2 RGB image with a different value in every channel of every pixel, mosaiced by
  // hand: rggb keeps R of (0,0), G of (1,0), G of (0,1), B of (1,1).
  Image rgb(2, 2, PixelFormat::kRgb8);
  for (int i = 0; i < 12; ++i) rgb.data()[i] = static_cast<uint8_t>(10 + i);
  const Image m = Mosaic(rgb.view(), CfaPattern::kRggb);
  EXPECT_EQ(m.format(), PixelFormat::kBayerRggb8);
  EXPECT_EQ(m.row(0)[0], 10);  // (0,0) R
  EXPECT_EQ(m.row(0)[1], 14);  // (1,0) G
  EXPECT_EQ(m.row(1)[0], 17);  // (0,1) G
  EXPECT_EQ(m.row(1)[1], 21);  // (1,1) B
  const Image g = Mosaic(rgb.view(), CfaPattern::kGbrg);
  EXPECT_EQ(g.row(0)[0], 11);  // (0,0) G
  EXPECT_EQ(g.row(0)[1], 15);  // (1,0) B
  EXPECT_EQ(g.row(1)[0], 16);  // (0,1) R
  EXPECT_EQ(g.row(1)[1], 20);  // (1,1) G
}

TEST(ColorFilter, OpenCVsCodeOfEachPatternGivesBackAUniformColour) {
  // The hand check of OpenCV's shifted names: a uniform colour mosaiced with a pattern comes
  // back as that colour only through the code named here (a wrong one swaps red and blue, or
  // puts green where red was).
  cv::Mat flat(6, 6, CV_8UC3, cv::Scalar(200, 100, 50));  // R G B
  const Image rgb = ImageOf(flat);
  for (CfaPattern pattern : kPatterns) {
    const Image mosaic = Mosaic(rgb.view(), pattern);
    cv::Mat back;
    cv::demosaicing(MatOf(mosaic), back, CvCode(pattern, DemosaicMethod::kBilinear), 3);
    for (int y = 0; y < 6; ++y) {
      for (int x = 0; x < 6; ++x) {
        EXPECT_EQ(back.at<cv::Vec3b>(y, x), cv::Vec3b(200, 100, 50))
            << ToString(pattern) << " " << OpenCVBayerCodeName(pattern) << " at " << x << "," << y;
      }
    }
  }
  EXPECT_STREQ(OpenCVBayerCodeName(CfaPattern::kRggb), "COLOR_BayerBG2RGB");
  EXPECT_STREQ(OpenCVBayerCodeName(CfaPattern::kBggr), "COLOR_BayerRG2RGB");
  EXPECT_STREQ(OpenCVBayerCodeName(CfaPattern::kGrbg), "COLOR_BayerGB2RGB");
  EXPECT_STREQ(OpenCVBayerCodeName(CfaPattern::kGbrg), "COLOR_BayerGR2RGB");
}

TEST(ColorFilter, BilinearDemosaicEqualsOpenCVBitForBit) {
  const std::vector<Image> images = [] {
    std::vector<Image> v;
    v.push_back(Cat());
    v.push_back(Noise(64, 48, 1));
    v.push_back(Noise(37, 23, 2));  // odd: a last column and row of half cells
    v.push_back(Noise(3, 3, 3));    // the smallest with an interior
    v.push_back(Noise(4, 5, 4));
    return v;
  }();
  for (const Image& rgb : images) {
    for (CfaPattern pattern : kPatterns) {
      EXPECT_EQ(CountDifferences(rgb, pattern, DemosaicMethod::kBilinear), 0)
          << ToString(pattern) << " " << rgb.width() << " x " << rgb.height();
    }
  }
}

TEST(ColorFilter, EdgeAwareDemosaicEqualsOpenCVBitForBit) {
  for (const Image& rgb : {Cat(), Noise(64, 48, 5), Noise(37, 23, 6), Noise(3, 3, 7)}) {
    for (CfaPattern pattern : kPatterns) {
      EXPECT_EQ(CountDifferences(rgb, pattern, DemosaicMethod::kEdgeAware), 0)
          << ToString(pattern) << " " << rgb.width() << " x " << rgb.height();
    }
  }
}

TEST(ColorFilter, ImagesWithoutAnInteriorComeOutBlackAsOpenCVs) {
  for (const auto& [w, h] : {std::pair{2, 2}, std::pair{2, 6}, std::pair{6, 2}}) {
    const Image mosaic = Mosaic(Noise(w, h, 8).view(), CfaPattern::kRggb);
    const Image ours = Demosaic(mosaic.view());
    cv::Mat reference;
    cv::demosaicing(MatOf(mosaic), reference, cv::COLOR_BayerBG2RGB, 3);
    EXPECT_EQ(cv::countNonZero(reference.reshape(1)), 0) << w << " x " << h;
    for (std::size_t i = 0; i < ours.size_bytes(); ++i) ASSERT_EQ(ours.data()[i], 0) << i;
  }
}

TEST(ColorFilter, DemosaicKeepsTheMetadata) {
  Image rgb = Noise(8, 8, 9);
  rgb.metadata().camera = "left";
  rgb.metadata().frame_index = 7;
  const Image back = Demosaic(Mosaic(rgb.view(), CfaPattern::kGrbg).view());
  EXPECT_EQ(back.metadata().camera, "left");
  EXPECT_EQ(back.metadata().frame_index, 7);
}

TEST(ToneCurve, TablesFollowTheirFormulas) {
  // Exact: the table is the formula rounded, so every entry is checked against the formula
  // written out here.
  ToneCurve linear;
  ToneCurve gamma{ToneCurveKind::kGamma, 2.2};
  ToneCurve srgb{ToneCurveKind::kSrgb};
  const auto lin = ToneTable(linear), gam = ToneTable(gamma), s = ToneTable(srgb);
  const auto gained = ToneTable(srgb, 1.5);
  for (int v = 0; v < 256; ++v) {
    const double l = v / 255.0;
    EXPECT_EQ(lin[v], v);
    EXPECT_EQ(gam[v], std::lround(255.0 * std::pow(l, 1.0 / 2.2))) << v;
    const double encoded = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1 / 2.4) - 0.055;
    EXPECT_EQ(s[v], std::lround(255.0 * encoded)) << v;
    const double lg = std::min(1.0, 1.5 * l);
    const double eg = lg <= 0.0031308 ? 12.92 * lg : 1.055 * std::pow(lg, 1 / 2.4) - 0.055;
    EXPECT_EQ(gained[v], std::lround(255.0 * eg)) << v;
  }
  // Known values of sRGB: mid grey 0.5 encodes to 0.7354 (188 of 255); 0.18 to 0.4613.
  EXPECT_NEAR(srgb.Encode(0.5), 0.735357, 1e-6);
  EXPECT_NEAR(srgb.Encode(0.18), 0.461356, 1e-6);
  // The two pieces meet at the break point.
  EXPECT_NEAR(12.92 * 0.0031308, 1.055 * std::pow(0.0031308, 1 / 2.4) - 0.055, 1e-6);
}

TEST(ColorPipeline, WhiteBalanceScalesEachColourOfTheMosaicThenDemosaics) {
  cv::Mat flat(8, 8, CV_8UC3, cv::Scalar(100, 100, 100));
  ColorOptions options;
  options.cfa = CfaPattern::kBggr;
  options.white_balance = {1.5, 1.0, 0.5};
  const ColorImages out = ApplyColorPipeline(ImageOf(flat).view(), options);
  ASSERT_EQ(out.raw.format(), PixelFormat::kBayerBggr8);
  EXPECT_EQ(out.raw.row(0)[0], 50);   // B
  EXPECT_EQ(out.raw.row(0)[1], 100);  // G
  EXPECT_EQ(out.raw.row(1)[1], 150);  // R
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      const uint8_t* p = out.rgb.row(y) + 3 * x;
      EXPECT_EQ(p[0], 150);
      EXPECT_EQ(p[1], 100);
      EXPECT_EQ(p[2], 50);
    }
  }
  // Without a filter array: the RGB image balanced and encoded, no raw image.
  options.cfa = CfaPattern::kNone;
  options.tone_curve = {ToneCurveKind::kSrgb};
  const ColorImages plain = ApplyColorPipeline(ImageOf(flat).view(), options);
  EXPECT_TRUE(plain.raw.empty());
  const auto table = ToneTable(options.tone_curve);
  EXPECT_EQ(plain.rgb.row(3)[9], table[150]);
  EXPECT_EQ(plain.rgb.row(3)[10], table[100]);
  EXPECT_EQ(plain.rgb.row(3)[11], table[50]);
}

// A mosaic's pipeline with a tone curve: OpenCV's demosaicing of the mosaic, then the curve's
// table on every value, borders included (the curve is applied row by row as rows are
// demosaiced).
TEST(ColorPipeline, AToneCurveEncodesOpenCVsDemosaicedImage) {
  const Image rgb = Noise(37, 23, 5);
  for (const ToneCurve curve :
       {ToneCurve{ToneCurveKind::kSrgb}, ToneCurve{ToneCurveKind::kGamma, 1.8}}) {
    for (const DemosaicMethod method : {DemosaicMethod::kBilinear, DemosaicMethod::kEdgeAware}) {
      SCOPED_TRACE(std::string(ToString(curve.kind)) + " " + ToString(method));
      ColorOptions options;
      options.cfa = CfaPattern::kGrbg;
      options.demosaic = method;
      options.tone_curve = curve;
      const ColorImages out = ApplyColorPipeline(rgb.view(), options);
      cv::Mat reference;
      cv::demosaicing(MatOf(out.raw), reference, CvCode(options.cfa, method), 3);
      const auto table = ToneTable(curve);
      int differ = 0, changed = 0;
      for (int y = 0; y < rgb.height(); ++y) {
        for (int x = 0; x < 3 * rgb.width(); ++x) {
          const uint8_t want = reference.ptr<uint8_t>(y)[x];
          differ += out.rgb.row(y)[x] != table[want];
          changed += table[want] != want;
        }
      }
      EXPECT_EQ(differ, 0);
      EXPECT_GT(changed, 1000);  // the curve is not the identity here
    }
  }
}

TEST(ColorFilter, ParsesPatternsAndRosEncodings) {
  EXPECT_EQ(ParseCfaPattern("rggb"), CfaPattern::kRggb);
  EXPECT_EQ(ParseCfaPattern("GBRG"), CfaPattern::kGbrg);
  EXPECT_EQ(ParseCfaPattern("none"), CfaPattern::kNone);
  EXPECT_EQ(ParseCfaPattern("bayer_grbg8"), CfaPattern::kGrbg);
  EXPECT_EQ(ParseCfaPattern("bayer_bggr16"), CfaPattern::kBggr);
  for (CfaPattern p : kPatterns) {
    EXPECT_EQ(ParseCfaPattern(ToString(p)), p);
    EXPECT_EQ(PatternOf(BayerFormat(p, 8)), p);
    EXPECT_EQ(PatternOf(BayerFormat(p, 16)), p);
    EXPECT_EQ(ParseCfaPattern(ToString(BayerFormat(p, 8))), p);
    EXPECT_EQ(std::string(ToString(BayerFormat(p, 16))),
              std::string("bayer_") + ToString(p) + "16");
  }
  EXPECT_EQ(PatternOf(PixelFormat::kGray8), CfaPattern::kNone);
  EXPECT_EQ(ParseDemosaicMethod("edge_aware"), DemosaicMethod::kEdgeAware);
  EXPECT_EQ(ParseToneCurveKind("sRGB"), ToneCurveKind::kSrgb);
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

TEST(ColorFilter, BadValuesAreRefusedNamingTheField) {
  using ::testing::HasSubstr;
  EXPECT_THAT(ErrorOf([] { ParseCfaPattern("rgbg", "camera.cfa"); }),
              AllOf(HasSubstr("camera.cfa"), HasSubstr("'rgbg'"), HasSubstr("rggb, bggr")));
  EXPECT_THAT(ErrorOf([] { ParseCfaPattern("bayer_rggb12"); }), HasSubstr("'bayer_rggb12'"));
  EXPECT_THAT(ErrorOf([] { ParseDemosaicMethod("vng"); }),
              AllOf(HasSubstr("demosaic"), HasSubstr("'vng'"), HasSubstr("edge_aware")));
  EXPECT_THAT(ErrorOf([] { ParseToneCurveKind("log"); }),
              AllOf(HasSubstr("tone_curve"), HasSubstr("'log'")));
  EXPECT_THAT(ErrorOf([] {
                WhiteBalance{1.0, 0.0, 1.0}.Validate();
              }),
              AllOf(HasSubstr("white_balance.green"), HasSubstr("got 0")));
  EXPECT_THAT(ErrorOf([] {
                WhiteBalance{NAN, 1.0, 1.0}.Validate();
              }),
              HasSubstr("white_balance.red"));
  EXPECT_THAT(ErrorOf([] {
                WhiteBalance{1.0, 1.0, -2.0}.Validate();
              }),
              AllOf(HasSubstr("white_balance.blue"), HasSubstr("-2")));
  EXPECT_THAT(ErrorOf([] {
                ToneCurve{ToneCurveKind::kGamma, 0.0}.Validate();
              }),
              AllOf(HasSubstr("tone_curve.gamma"), HasSubstr("got 0")));
  EXPECT_THAT(ErrorOf([] { Mosaic(Image(4, 4, PixelFormat::kRgb8).view(), CfaPattern::kNone); }),
              HasSubstr("'none' has no mosaic"));
  EXPECT_THAT(ErrorOf([] { Mosaic(Image(4, 4, PixelFormat::kGray8).view(), CfaPattern::kRggb); }),
              HasSubstr("gray8, expected rgb8"));
  EXPECT_THAT(ErrorOf([] { Demosaic(Image(4, 4, PixelFormat::kGray8).view()); }),
              HasSubstr("expected an 8-bit Bayer mosaic"));
  EXPECT_THAT(ErrorOf([] { Demosaic(Image(4, 4, PixelFormat::kBayerRggb16).view()); }),
              HasSubstr("bayer_rggb16"));
}

}  // namespace
}  // namespace saccade::render
