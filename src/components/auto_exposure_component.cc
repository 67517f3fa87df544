#include "saccade/components/auto_exposure_component.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "saccade/core/error.h"
#include "saccade/scene/camera_controls.h"

namespace saccade::components {

namespace {
// The darkest brightness the loop divides by: half a DN, so that a black frame asks for the
// largest step rather than an infinite one.
constexpr double kMinBrightness = 0.5 / 255.0;
constexpr double kLn10Over20 = 0.11512925464970229;  // ln(10) / 20
}  // namespace

AutoExposureComponent::AutoExposureComponent()
    : image_(AddInput<runtime::ImageMessage>("image", /*required=*/true)),
      controls_(AddOutput<CameraControlsMessage>("controls")) {
  DeclareParam("camera", &camera_,
               "the camera to command: a camera's name, \"all\" (every camera follows this "
               "one's meter, as a stereo pair should), or empty for the image's own camera");
  DeclareParam("target", &target_, "the mean brightness to hold, a fraction of full scale")
      .Range(0.01, 0.99);
  DeclareParam("min_exposure_s", &min_exposure_s_, "the shortest exposure commanded")
      .Range(1e-6, scene::kMaxExposureS)
      .Unit("s");
  DeclareParam("max_exposure_s", &max_exposure_s_,
               "the longest exposure commanded (then the gain rises)")
      .Range(1e-6, scene::kMaxExposureS)
      .Unit("s");
  DeclareParam("max_gain_db", &max_gain_db_, "the largest gain commanded")
      .Range(0.0, scene::kMaxGainDb)
      .Unit("dB");
  DeclareParam("damping", &damping_,
               "the fraction of the way from the last command to the ideal setting moved per "
               "frame (1: all at once)")
      .Range(0.01, 1.0);
  DeclareParam("deadband", &deadband_,
               "no command while |ln(brightness / target)| is below this (noise does not "
               "chatter the exposure)")
      .Range(0.0, 1.0);
  DeclareParam("subsample", &subsample_, "the meter reads every n-th pixel of every n-th row")
      .Range(1, 64)
      .Unit("px");
  DeclareParam("centre_weight", &centre_weight_,
               "centre-weighted metering: weight 1 - centre_weight * r^2 (r: distance from the "
               "centre over the half-diagonal); 0: uniform")
      .Range(0.0, 1.0);
}

void AutoExposureComponent::Configured() {
  if (min_exposure_s_ > max_exposure_s_) {
    throw InvalidArgument(
        fmt::format("parameter 'min_exposure_s': expected at most max_exposure_s ({} s), got {} s",
                    max_exposure_s_, min_exposure_s_));
  }
}

double AutoExposureComponent::MeasureBrightness(const Image& image, int subsample,
                                                double centre_weight) {
  const int channels = static_cast<int>(BytesPerPixel(image.format()));
  const double cx = 0.5 * (image.width() - 1), cy = 0.5 * (image.height() - 1);
  const double r2_max = std::max(1e-12, cx * cx + cy * cy);
  double sum = 0.0, weights = 0.0;
  for (int y = subsample / 2; y < image.height(); y += subsample) {
    const uint8_t* row = image.row(y);
    for (int x = subsample / 2; x < image.width(); x += subsample) {
      const uint8_t* p = row + static_cast<std::size_t>(x) * channels;
      const double luma = channels >= 3 ? 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2] : p[0];
      const double r2 = ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / r2_max;
      const double w = 1.0 - centre_weight * r2;
      sum += w * luma;
      weights += w;
    }
  }
  return weights > 0.0 ? sum / weights / 255.0 : 0.0;
}

void AutoExposureComponent::Step(const runtime::StepContext& context) {
  const runtime::ImageMessage* message = image_.get();
  if (message == nullptr || !image_.fresh() || !message->image) return;
  const Image& image = *message->image;
  if (image.format() != PixelFormat::kRgb8 && image.format() != PixelFormat::kGray8) {
    throw InvalidArgument(fmt::format("{}: input 'image': expected rgb8 or gray8, got {}", name(),
                                      ToString(image.format())));
  }
  const double brightness = MeasureBrightness(image, subsample_, centre_weight_);
  const double error = std::log(target_ / std::max(brightness, kMinBrightness));
  if (std::abs(error) < deadband_) return;
  const ImageMetadata& meta = image.metadata();
  const double exposure_frame = meta.exposure_s > 0.0 ? meta.exposure_s : scene::kNominalExposureS;
  const double frame_setting = std::log(exposure_frame) + meta.gain_db * kLn10Over20;
  const double ideal = frame_setting + error;
  const double from = last_setting_.value_or(frame_setting);
  const double setting = from + damping_ * (ideal - from);
  const double exposure = std::clamp(std::exp(setting), min_exposure_s_, max_exposure_s_);
  const double gain_db =
      std::clamp((setting - std::log(exposure)) / kLn10Over20, 0.0, max_gain_db_);
  last_setting_ = std::log(exposure) + gain_db * kLn10Over20;  // what the camera can do
  CameraControlsMessage out;
  out.time = context.time;
  out.commands.push_back({camera_.empty() ? meta.camera : camera_, exposure, gain_db, {}});
  controls_.Emit(out);
}

}  // namespace saccade::components
