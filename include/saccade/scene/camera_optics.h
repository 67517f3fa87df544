#pragma once
// A camera's photometric chain as a scene file states it (issue 45; docs/camera-pixels.md):
// its colour (a colour filter array, demosaicing, white balance, a tone curve: a sensor's
// `color`) and the photometric side of its lens (vignetting, a thin lens's depth of field: a
// camera's `lens`). Plain data, validated by the scene loader; render/color_filter.h and
// render/lens_optics.h define the models and apply them (render/camera_chain.h converts).
// Every default is "off": a camera without these keys renders as before, bit for bit.

#include <array>

namespace saccade::scene {

/// A colour filter array's 2 x 2 cell, read row by row from pixel (0, 0), as ROS names its
/// Bayer encodings; kNone: no filter (the image stays RGB). render::CfaPattern is this type.
enum class CfaPattern { kNone, kRggb, kBggr, kGrbg, kGbrg };
/// How a mosaic is demosaiced (render::DemosaicMethod is this type).
enum class DemosaicMethod {
  kBilinear,   ///< cv::COLOR_Bayer**2RGB: each missing colour the mean of its 2 or 4 nearest
  kEdgeAware,  ///< cv::COLOR_Bayer**2RGB_EA: green along the smaller gradient
};
/// How linear values are encoded into the image's 8 bits (render::ToneCurveKind is this type).
enum class ToneCurveKind {
  kLinear,  ///< V = L
  kGamma,   ///< V = L^(1 / gamma)
  kSrgb,    ///< IEC 61966-2-1: V = 12.92 L for L <= 0.0031308, else 1.055 L^(1/2.4) - 0.055
};
/// How vignetting is modelled (render::VignettingModel is this type).
enum class VignettingModel { kNone, kCos4, kPolynomial };

/// A sensor's colour (SensorSpec::color).
struct ColorSpec {
  CfaPattern cfa = CfaPattern::kNone;
  DemosaicMethod demosaic = DemosaicMethod::kBilinear;
  /// White balance gains on the linear red, green and blue values, each finite and > 0.
  std::array<double, 3> white_balance{1.0, 1.0, 1.0};
  ToneCurveKind tone_curve = ToneCurveKind::kLinear;
  double gamma = 2.2;  ///< of kGamma: finite, > 0

  /// Anything to do: a filter array, a gain other than 1 or a tone curve other than linear.
  bool Enabled() const {
    return cfa != CfaPattern::kNone || white_balance != std::array<double, 3>{1.0, 1.0, 1.0} ||
           tone_curve != ToneCurveKind::kLinear;
  }
};

/// The photometric side of a camera's lens (CameraSpec::lens). Lengths in metres.
struct LensSpec {
  VignettingModel vignetting = VignettingModel::kNone;
  /// a1, a2, a3 of kPolynomial: 1 + a1 r^2 + a2 r^4 + a3 r^6, r = 1 at the farthest corner.
  std::array<double, 3> vignetting_coefficients{0.0, 0.0, 0.0};
  /// Thin-lens depth of field, drawn from the depth of each frame (f_number > 0: on).
  double f_number = 0.0;          ///< N; 0: no depth of field
  double focal_length_m = 0.0;    ///< f, > 0 with depth of field
  double focus_distance_m = 0.0;  ///< s, > f: where the lens focuses (a frame may override)
  double pixel_pitch_m = 0.0;     ///< 0: f / fx across and f / fy down
  double max_coc_px = 32.0;       ///< the largest circle drawn, pixels, >= 1

  bool HasVignetting() const { return vignetting != VignettingModel::kNone; }
  bool HasDepthOfField() const { return f_number > 0.0; }
  bool Enabled() const { return HasVignetting() || HasDepthOfField(); }
};

}  // namespace saccade::scene
