#pragma once
// The real robot as pipeline components (issue 7; seed Fig. 2: popeyeRobot and the camera
// acquisition): the same component names and ports as sim.head and sim.cameras, so that a
// hardware file (runtime/pipeline.h) swaps one for the other.
//
// hw.cameras -- the eye cameras as real camera sources (hw/camera_source.h: V4L2 devices,
//   GStreamer pipelines, IIDC cameras, video files, image sequences and lists), paired by
//   time stamp (hw/stereo_source.h), delivering the same images with the same metadata as
//   sim.cameras: K and distortion from each camera's calibration file, X_WC and the joints
//   from the head's forward kinematics at the joints of this step.
//   Its scene's robot carries the cameras. Parameters: declared in the constructor
//   (docs/components.md); each camera's SOURCE map is read by a table of its own.
//   inputs:  joints (head.joints, optional; connect with delay 1 as for sim.cameras)
//   outputs: left, right (runtime.image): one pair per step; time = the step's time (the
//            capture time stays in the source: frame_index counts the pairs delivered)
//   When a file or list ends (without loop), nothing more is emitted and a log line (info)
//   says so; a device error stops the pipeline with the camera and its uri named.
#include <memory>
#include <optional>
#include <string>

#include "saccade/components/messages.h"
#include "saccade/components/roles.h"
#include "saccade/head/motors.h"
#include "saccade/hw/head_driver.h"
#include "saccade/hw/stereo_source.h"
#include "saccade/runtime/component.h"
#include "saccade/scene/scene.h"

namespace saccade::components {

class HwCameras : public runtime::Component, public EyeCamerasRole {
 public:
  HwCameras();
  void Start() override;
  void Step(const runtime::StepContext& context) override;
  void Stop() override;

  /// The pair source, once started (tests, tools).
  const hw::StereoSource* source() const { return source_.get(); }
  /// The scene whose robot carries the cameras (not what they see).
  const scene::Scene& scene() const override { return *scene_; }
  /// Pairs delivered, and frames dropped for want of a partner within max_skew_s, so far.
  int64_t pairs() const { return pairs_; }
  int64_t dropped_left() const { return dropped_left_; }
  int64_t dropped_right() const { return dropped_right_; }
  /// A line for people: "25 pairs from <left uri> and <right uri>, 0 + 0 frames dropped".
  std::string Describe() const override;
  std::optional<CameraPairCounts> pair_counts() const override {
    return CameraPairCounts{pairs_, dropped_left_, dropped_right_};
  }

 protected:
  void Configured() override;

 private:
  std::string scene_param_;
  nlohmann::json cameras_;
  runtime::Input<JointStateMessage>& joints_;
  runtime::Output<runtime::ImageMessage>& left_;
  runtime::Output<runtime::ImageMessage>& right_;
  std::shared_ptr<const scene::Scene> scene_;
  hw::CameraSourceSpec left_spec_;
  hw::CameraSourceSpec right_spec_;
  double max_skew_s_ = 0.02;
  std::unique_ptr<hw::StereoSource> source_;
  bool ended_ = false;
  int64_t pairs_ = 0;
  int64_t dropped_left_ = 0;
  int64_t dropped_right_ = 0;
};

}  // namespace saccade::components
