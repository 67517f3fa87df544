#pragma once
// camera.auto_exposure -- holds one camera's mean brightness at a target by commanding its
//   exposure time, then its gain (a machine-vision camera's auto-exposure loop).
//   inputs:  image (runtime.image, required): the camera's frames; their metadata's exposure
//            and gain (what the frame was taken with) are the loop's feedback.
//   outputs: controls (camera.controls): a command when the brightness is off the target by
//            more than `deadband`; connect it to sim.cameras' (or a real camera's) `controls`
//            input with `delay: 1`.
//
// The loop, per frame (brightness m: the mean luma, 0.299 R + 0.587 G + 0.114 B over full
// scale, of every `subsample`-th pixel of every `subsample`-th row, weighted by
// 1 - centre_weight * r^2 with r the distance from the centre over the half-diagonal), in log
// exposure x gain (L = ln exposure_s + gain_dB * ln(10) / 20):
//   L_ideal  = L_frame + ln(target / max(m, 0.5 / 255))
//   L_new    = L_last + damping * (L_ideal - L_last)
//   exposure = clamp(e^L_new, min_exposure_s, max_exposure_s)
//   gain_dB  = clamp((L_new - ln exposure) * 20 / ln(10), 0, max_gain_db)
// where L_frame is what the frame was taken with and L_last the last command (L_frame at
// first).
// L_ideal comes from the frame's own setting (its metadata), so a frame taken before the last
// command applied (the camera's latency) estimates the same ideal rather than asking for the
// step again: the loop does not wind up. The command approaches the ideal by the factor
// 1 - damping per frame, monotonically, and the brightness follows it a latency later: no
// overshoot for a brightness proportional to exposure x gain (damping <= 1). No command while
// |ln(target / m)| < deadband. A frame whose exposure is 0 (an instant: the file gives none)
// counts as scene::kNominalExposureS.
// Parameters: declared in the constructor (docs/components.md lists them).
#include <optional>
#include <string>

#include "saccade/components/messages.h"
#include "saccade/core/image.h"
#include "saccade/runtime/component.h"

namespace saccade::components {

class AutoExposureComponent : public runtime::Component {
 public:
  AutoExposureComponent();
  void Step(const runtime::StepContext& context) override;

  /// The brightness the loop measures on `image` (kRgb8 or kGray8), in [0, 1].
  static double MeasureBrightness(const Image& image, int subsample, double centre_weight);

 protected:
  void Configured() override;

 private:
  runtime::Input<runtime::ImageMessage>& image_;
  runtime::Output<CameraControlsMessage>& controls_;
  std::string camera_;  // "" : the image's camera
  double target_ = 0.45;
  double min_exposure_s_ = 1e-4;
  double max_exposure_s_ = 0.02;
  double max_gain_db_ = 24.0;
  double damping_ = 0.5;
  double deadband_ = 0.02;
  int subsample_ = 4;
  double centre_weight_ = 0.0;
  std::optional<double> last_setting_;  // L of the last command
};

}  // namespace saccade::components
