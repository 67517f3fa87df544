#pragma once
// Colour as a camera makes it (issue 45; docs/camera-pixels.md): a colour filter array (CFA)
// samples one colour a pixel, the mosaic is demosaiced back to RGB, white balance gains scale
// the channels and a tone curve encodes the values. CPU only, no GL, no OpenCV.
//
// Patterns are named as ROS names its encodings (sensor_msgs/image_encodings.hpp): the 2 x 2
// cell read row by row from pixel (0, 0), so kRggb has R at (0, 0), G at (1, 0) and (0, 1) and
// B at (1, 1). OpenCV names its Bayer codes by the cell at (1, 1) instead: kRggb is
// cv::COLOR_BayerBG2RGB, kBggr COLOR_BayerRG2RGB, kGrbg COLOR_BayerGB2RGB and kGbrg
// COLOR_BayerGR2RGB (OpenCVBayerCodeName; tests/render/color_filter_test.cc pins it).
//
// Values are taken as linear in the scene's radiance (the renderer's 8-bit colours), so the
// order of a camera is: Mosaic (the sensor), white balance, Demosaic, then the tone curve
// (ApplyColorPipeline). Every function here is thread-safe; the per-pixel ones do not throw.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "saccade/core/image.h"
#include "saccade/scene/camera_optics.h"

namespace saccade::render {

/// A colour filter array's 2 x 2 cell, read row by row from pixel (0, 0); kNone: no filter
/// (the image stays RGB). The scene's type (scene/camera_optics.h), which its files name.
using CfaPattern = scene::CfaPattern;

/// "none", "rggb", "bggr", "grbg", "gbrg".
const char* ToString(CfaPattern pattern);
/// A pattern from "none", "rggb", "bggr", "grbg", "gbrg" or a ROS Bayer encoding
/// ("bayer_rggb8", "bayer_rggb16", ...), upper or lower case. Throws InvalidArgument naming
/// `field`, the text and the names it accepts.
CfaPattern ParseCfaPattern(std::string_view text, std::string_view field = "cfa");
/// The pixel format of a pattern's mosaic: kBayerRggb8 ... (bits 8) or kBayerRggb16 ...
/// (bits 16). Throws InvalidArgument for kNone or other bits.
PixelFormat BayerFormat(CfaPattern pattern, int bits = 8);
/// The pattern of a Bayer pixel format; kNone for any other format.
CfaPattern PatternOf(PixelFormat format);
/// The colour a pattern samples at pixel (x, y): 0 red, 1 green, 2 blue (kNone: -1).
int CfaChannel(CfaPattern pattern, int x, int y);
/// OpenCV's name of the demosaicing code that reads this pattern into RGB
/// ("COLOR_BayerBG2RGB" for kRggb, ...; "" for kNone): for documents and messages.
const char* OpenCVBayerCodeName(CfaPattern pattern);

/// How a mosaic is demosaiced (kBilinear, kEdgeAware); both reproduce cv::demosaicing bit for
/// bit. The scene's type (scene/camera_optics.h).
using DemosaicMethod = scene::DemosaicMethod;
/// "bilinear", "edge_aware".
const char* ToString(DemosaicMethod method);
/// A method from "bilinear" or "edge_aware" (also "ea"); throws InvalidArgument naming `field`.
DemosaicMethod ParseDemosaicMethod(std::string_view text, std::string_view field = "demosaic");

/// The sensor's mosaic of an RGB image: pixel (x, y) keeps the colour CfaChannel says, in a
/// BayerFormat(pattern, 8) image with `rgb`'s size and metadata (when the view has any).
/// Throws InvalidArgument when `rgb` is not kRgb8 or `pattern` is kNone.
Image Mosaic(const ImageView& rgb, CfaPattern pattern);

/// The kRgb8 image of an 8-bit Bayer mosaic (kBayer*8), with its metadata, as cv::demosaicing
/// with the pattern's code (OpenCVBayerCodeName, "_EA" for kEdgeAware) computes it, bit for bit,
/// borders included: the interior from each pixel's 3 x 3 neighbours, rounded as OpenCV rounds
/// ((a + b + 1) >> 1 of two, (a + b + c + d + 2) >> 2 of four), then the
/// first and last columns copied from their neighbours, then the first and last rows.
/// Images narrower or shorter than 3 pixels come out black, as OpenCV's do. Throws
/// InvalidArgument for another format.
Image Demosaic(const ImageView& mosaic, DemosaicMethod method = DemosaicMethod::kBilinear);

/// White balance: gains on the linear red, green and blue values (the result clipped to the
/// 8-bit range). Each gain finite and > 0.
struct WhiteBalance {
  double red = 1.0;
  double green = 1.0;
  double blue = 1.0;
  /// Throws InvalidArgument naming the gain ("white_balance.red: ...") and its value.
  void Validate() const;
  /// The gain of channel 0 (red), 1 (green) or 2 (blue).
  double Gain(int channel) const { return channel == 0 ? red : (channel == 1 ? green : blue); }
};

/// How linear values are encoded into the image's 8 bits (kLinear, kGamma, kSrgb). The
/// scene's type (scene/camera_optics.h).
using ToneCurveKind = scene::ToneCurveKind;
/// "linear", "gamma", "srgb".
const char* ToString(ToneCurveKind kind);
/// A kind from "linear", "gamma" or "srgb"; throws InvalidArgument naming `field`.
ToneCurveKind ParseToneCurveKind(std::string_view text, std::string_view field = "tone_curve");

/// A tone curve: linear value L in [0, 1] to encoded value V in [0, 1].
struct ToneCurve {
  ToneCurveKind kind = ToneCurveKind::kLinear;
  /// The display gamma of kGamma (2.2 is common): finite, > 0.
  double gamma = 2.2;
  /// Throws InvalidArgument naming "tone_curve.gamma" and its value.
  void Validate() const;
  /// V of L (L clamped to [0, 1]).
  double Encode(double linear) const;
};

/// The table of an 8-bit channel through a gain and a tone curve: entry v is
/// round(255 * curve.Encode(min(1, gain * v / 255))). Throws as the options' Validate, and
/// InvalidArgument for a gain that is not finite and > 0.
std::array<uint8_t, 256> ToneTable(const ToneCurve& curve, double gain = 1.0);

/// White balance and tone curve of an RGB image in place (each channel through its ToneTable).
/// Throws InvalidArgument when the image is not kRgb8 or an option is invalid.
void ApplyWhiteBalanceAndTone(Image& rgb, const WhiteBalance& balance, const ToneCurve& curve);
/// White balance of an 8-bit mosaic in place: each pixel times the gain of the colour its
/// filter passes (what a sensor's analogue or digital gains per channel do), clipped to 255.
/// Throws InvalidArgument when the image is not an 8-bit Bayer mosaic or a gain is invalid.
void ApplyWhiteBalanceToMosaic(Image& mosaic, const WhiteBalance& balance);

/// A camera's colour: its filter array, how the mosaic is demosaiced, white balance and tone.
struct ColorOptions {
  CfaPattern cfa = CfaPattern::kNone;
  DemosaicMethod demosaic = DemosaicMethod::kBilinear;
  WhiteBalance white_balance;
  ToneCurve tone_curve;
  /// Throws InvalidArgument naming the field (white_balance.*, tone_curve.gamma).
  void Validate() const;
};

/// What a camera makes of one rendered image.
struct ColorImages {
  /// The raw mosaic after white balance, before the tone curve (kBayer*8); empty for kNone.
  Image raw;
  /// The image: demosaiced (or, with kNone, the input white balanced), then tone encoded.
  Image rgb;
};

/// The colour pipeline of a camera on a linear kRgb8 image: Mosaic, ApplyWhiteBalanceToMosaic,
/// Demosaic, then the tone curve; without a filter array, white balance and tone on the RGB.
/// Throws InvalidArgument for another format or invalid options.
ColorImages ApplyColorPipeline(const ImageView& linear_rgb, const ColorOptions& options);
/// The same from the sensor's mosaic (kBayer*8 of options.cfa's pattern: Mosaic's, then a
/// sensor's noise): white balance, Demosaic, tone. Throws InvalidArgument when options.cfa is
/// kNone, the mosaic's pattern differs, or an option is invalid.
ColorImages ApplyColorPipelineToMosaic(Image mosaic, const ColorOptions& options);

}  // namespace saccade::render
