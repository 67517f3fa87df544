#pragma once
// A camera's photometric chain on the frames read back (issue 45; docs/camera-pixels.md), light
// first: the lens (vignetting, depth of field) on linear values, then the sensor (the legacy
// noise or the EMVA 1288 sensor, applied by the renderer between the two halves), then the
// colour filter array's mosaic, white balance, demosaicing and the tone curve. CPU only.
//
// The scene states it (scene::LensSpec, scene::ColorSpec); the values that may change from frame
// to frame (the focus distance) are resolved once per frame and camera into FrameOptics, so that
// a command of a pipeline can override them.

#include <memory>

#include "saccade/core/image.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/render/color_filter.h"
#include "saccade/render/lens_optics.h"
#include "saccade/scene/scene.h"

namespace saccade::render {

/// The render library's options of a scene's colour and lens.
ColorOptions ToColorOptions(const scene::ColorSpec& color);
VignettingOptions ToVignettingOptions(const scene::LensSpec& lens);
/// The thin lens of `lens` focused at `focus_distance_m` (metres).
ThinLensOptions ToThinLensOptions(const scene::LensSpec& lens, double focus_distance_m);

/// The values of one frame of one camera that a frame may change.
struct FrameOptics {
  double focus_distance_m = 0.0;  ///< the thin lens's focus distance (depth of field)
};

/// One camera's chain: what the scene and the renderer's switches (RendererOptions::optics,
/// color) leave on, and the vignetting factors of its image, computed once.
class CameraChain {
 public:
  /// `rendered`: the camera model of the frames (the distortion, or the pinhole of K when
  /// distortion is off), whose rays give cos^4 vignetting. Throws InvalidArgument on invalid
  /// options.
  CameraChain(const scene::CameraSpec& camera, const geometry::CameraModel& rendered, bool optics,
              bool color);

  bool vignetting() const { return vignetting_; }
  bool depth_of_field() const { return depth_of_field_; }
  /// Vignetting or depth of field: the lens half of the chain, before the sensor.
  bool optics() const { return vignetting_ || depth_of_field_; }
  bool color() const { return color_; }
  bool cfa() const { return color_ && options_.cfa != CfaPattern::kNone; }
  const ColorOptions& color_options() const { return options_; }

  /// The frame's values from the scene (the lens's focus distance).
  FrameOptics FrameDefaults() const;
  /// The frame's values with a commanded focus distance (`focus_m` > 0; 0: the scene's). A
  /// lens does not focus nearer than its focal length: a command nearer focuses at
  /// kNearestFocus times the focal length.
  FrameOptics FrameOf(double focus_m) const;
  static constexpr double kNearestFocus = 1.01;
  /// Vignetting, then depth of field from `depth` (kFloat32, Frame::depth's meaning; needed
  /// when depth_of_field()), on a kRgb8 image in place.
  void ApplyOptics(Image* rgb, const Image* depth, const FrameOptics& frame) const;
  /// The same, returned as the mosaic of the filter array (needs cfa()): Mosaic of ApplyOptics'
  /// image to the bit, the depth of field gathered for each pixel's own colour only
  /// (ApplyDepthOfFieldToMosaic). `rgb` is left vignetted, not blurred.
  Image ApplyOpticsToMosaic(Image* rgb, const Image* depth, const FrameOptics& frame) const;
  /// The colour half on a kRgb8 image in place (the demosaiced, tone-encoded image); returns
  /// the raw mosaic (kBayer*8, white balanced, with the image's metadata) when there is a
  /// filter array, else null. `mosaic` (with a filter array): the sensor's mosaic of `rgb`
  /// (Mosaic, then exposed by the sensor) to demosaic instead of mosaicing `rgb`; moved from.
  std::shared_ptr<Image> ApplyColor(Image* rgb, Image* mosaic = nullptr) const;

 private:
  scene::LensSpec lens_;
  geometry::Intrinsics intrinsics_;
  ColorOptions options_;
  bool vignetting_ = false;
  bool depth_of_field_ = false;
  bool color_ = false;
  Image factors_;  // VignettingFactors
};

}  // namespace saccade::render
