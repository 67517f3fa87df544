#pragma once
// camera.accommodation -- focuses both eyes at the distance they verge to, as an active-vision
//   head accommodates: from the two images' poses alone (X_WC in every image's metadata,
//   geometry/image_camera.h), so it works on any head, a URDF's included, and on a real robot.
//   inputs:  left, right (runtime.image, required): the two eyes' frames of one step;
//            controls (camera.controls, optional): commands to pass on ahead of this one's
//            (an auto exposure's), since a camera's `controls` input has one source.
//   outputs: controls (camera.controls): each eye's focus_m, for the cameras the images name;
//            connect it to sim.cameras' `controls` input with `delay: 1`.
//
// The vergence point is where the optical axes come closest (head::FixationPoint: the
// midpoint of their common perpendicular). Each eye focuses at that point's depth along its
// own optical axis, (p - o) . z_C, which is its distance when the axes meet; clamped to
// [min_focus_m, max_focus_m]. Parallel axes, or axes that meet behind an eye (diverging
// eyes): max_focus_m (far).
// Parameters: declared in the constructor (docs/components.md lists them).
#include <Eigen/Core>
#include <optional>

#include "saccade/components/messages.h"
#include "saccade/geometry/pose.h"
#include "saccade/runtime/component.h"

namespace saccade::components {

class AccommodationComponent : public runtime::Component {
 public:
  AccommodationComponent();
  void Step(const runtime::StepContext& context) override;

  /// Each eye's focus distance (left, right) for eye poses X_WLeft and X_WRight, clamped to
  /// [min_focus_m, max_focus_m]; max_focus_m when the axes do not meet in front.
  static Eigen::Vector2d FocusDistances(const geometry::Pose& X_WLeft,
                                        const geometry::Pose& X_WRight, double min_focus_m,
                                        double max_focus_m);

 protected:
  void Configured() override;

 private:
  runtime::Input<runtime::ImageMessage>& left_;
  runtime::Input<runtime::ImageMessage>& right_;
  runtime::Input<CameraControlsMessage>& upstream_;
  runtime::Output<CameraControlsMessage>& controls_;
  double min_focus_m_ = 0.1;
  double max_focus_m_ = 100.0;
};

}  // namespace saccade::components
