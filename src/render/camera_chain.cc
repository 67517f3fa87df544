#include "saccade/render/camera_chain.h"

#include <algorithm>
#include <cstring>
#include <utility>

#include "saccade/core/error.h"

namespace saccade::render {
namespace {

// `pixels`, an image of `image`'s size and format, become `image`'s pixels; `image` keeps its
// metadata (a move of the buffer where the chain's result had been copied row by row).
void TakePixels(Image* image, Image pixels) {
  SACCADE_ASSERT(pixels.width() == image->width() && pixels.height() == image->height() &&
                     pixels.format() == image->format(),
                 "CameraChain: a result of another size or format than its image");
  pixels.metadata() = std::move(image->metadata());
  *image = std::move(pixels);
}

}  // namespace

ColorOptions ToColorOptions(const scene::ColorSpec& color) {
  ColorOptions options;
  options.cfa = color.cfa;
  options.demosaic = color.demosaic;
  options.white_balance = {color.white_balance[0], color.white_balance[1], color.white_balance[2]};
  options.tone_curve.kind = color.tone_curve;
  options.tone_curve.gamma = color.gamma;
  return options;
}

VignettingOptions ToVignettingOptions(const scene::LensSpec& lens) {
  VignettingOptions options;
  options.model = lens.vignetting;
  options.coefficients = lens.vignetting_coefficients;
  return options;
}

ThinLensOptions ToThinLensOptions(const scene::LensSpec& lens, double focus_distance_m) {
  ThinLensOptions options;
  options.focal_length_m = lens.focal_length_m;
  options.f_number = lens.f_number;
  options.focus_distance_m = focus_distance_m;
  options.pixel_pitch_m = lens.pixel_pitch_m;
  options.max_coc_px = lens.max_coc_px;
  return options;
}

CameraChain::CameraChain(const scene::CameraSpec& camera, const geometry::CameraModel& rendered,
                         bool optics, bool color)
    : lens_(camera.lens),
      intrinsics_(rendered.intrinsics()),
      options_(ToColorOptions(camera.sensor.color)),
      vignetting_(optics && camera.lens.HasVignetting()),
      depth_of_field_(optics && camera.lens.HasDepthOfField()),
      color_(color && camera.sensor.color.Enabled()) {
  if (color_) options_.Validate();
  if (depth_of_field_) ToThinLensOptions(lens_, lens_.focus_distance_m).Validate();
  if (vignetting_) factors_ = VignettingFactors(rendered, ToVignettingOptions(lens_));
}

FrameOptics CameraChain::FrameDefaults() const {
  FrameOptics frame;
  frame.focus_distance_m = lens_.focus_distance_m;
  return frame;
}

FrameOptics CameraChain::FrameOf(double focus_m) const {
  FrameOptics frame = FrameDefaults();
  if (focus_m > 0.0) {
    frame.focus_distance_m = std::max(focus_m, kNearestFocus * lens_.focal_length_m);
  }
  return frame;
}

void CameraChain::ApplyOptics(Image* rgb, const Image* depth, const FrameOptics& frame) const {
  if (vignetting_) ApplyVignetting(*rgb, factors_);
  if (!depth_of_field_) return;
  if (depth == nullptr) throw Error("CameraChain::ApplyOptics: depth of field without a depth");
  Image blurred = ApplyDepthOfField(rgb->view(), depth->view(),
                                    ToThinLensOptions(lens_, frame.focus_distance_m), intrinsics_);
  TakePixels(rgb, std::move(blurred));
}

Image CameraChain::ApplyOpticsToMosaic(Image* rgb, const Image* depth,
                                       const FrameOptics& frame) const {
  if (!cfa()) throw Error("CameraChain::ApplyOpticsToMosaic: the camera has no filter array");
  if (vignetting_) ApplyVignetting(*rgb, factors_);
  if (!depth_of_field_) return Mosaic(rgb->view(), options_.cfa);
  if (depth == nullptr) {
    throw Error("CameraChain::ApplyOpticsToMosaic: depth of field without a depth");
  }
  return ApplyDepthOfFieldToMosaic(rgb->view(), depth->view(),
                                   ToThinLensOptions(lens_, frame.focus_distance_m), intrinsics_,
                                   options_.cfa);
}

std::shared_ptr<Image> CameraChain::ApplyColor(Image* rgb, Image* mosaic) const {
  if (!color_) return nullptr;
  ColorImages images = mosaic != nullptr && options_.cfa != CfaPattern::kNone
                           ? ApplyColorPipelineToMosaic(std::move(*mosaic), options_)
                           : ApplyColorPipeline(rgb->view(), options_);
  TakePixels(rgb, std::move(images.rgb));
  if (options_.cfa == CfaPattern::kNone) return nullptr;
  images.raw.metadata() = rgb->metadata();
  return std::make_shared<Image>(std::move(images.raw));
}

}  // namespace saccade::render
