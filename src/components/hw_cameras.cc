#include "saccade/components/hw_cameras.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "components/internal_scene.h"
#include "saccade/core/error.h"
#include "saccade/core/log.h"
#include "saccade/geometry/image_camera.h"
#include "saccade/head/kinematics.h"
#include "saccade/hw/dynamixel_head.h"
namespace saccade::components {

namespace {

// One camera's source from `cameras.<name>`: {uri, calibration, calibration_index, fps, loop,
// first, every}; relative paths against `base_dir`.
hw::CameraSourceSpec ReadSource(const nlohmann::json& json, const std::string& name,
                                const std::string& base_dir) {
  const std::string key = "cameras." + name;
  if (!json.is_object()) {
    throw InvalidArgument(
        fmt::format("parameter '{}': expected a map {{uri, calibration, ...}}, "
                    "got {}",
                    key, json.dump()));
  }
  hw::CameraSourceSpec spec;
  spec.name = name;
  runtime::ParamTable p;
  p.Declare("uri", &spec.uri, "the source (hw/camera_source.h)").Required();
  p.Declare("calibration", &spec.calibration, "calibration file").Path();
  p.Declare("calibration_index", &spec.calibration_index, "camera in a stereo calibration")
      .Range(0, 2);
  p.Declare("fps", &spec.fps, "pace of a file source; 0: as fast as asked")
      .Range(0.0, 1e6)
      .Unit("Hz");
  p.Declare("loop", &spec.loop, "start a file source again at its end");
  p.Declare("first", &spec.first, "frames skipped at the start").Range(0, 1000000);
  p.Declare("every", &spec.every, "every n-th frame").Range(1, 1000000);
  try {
    p.Apply(json);
  } catch (const InvalidArgument& error) {
    // "parameter 'uri': ..." -> "parameter 'cameras.left.uri': ...", and so for "unknown
    // parameter 'url'".
    std::string message = error.what();
    const std::string from = "parameter '";
    const std::size_t at = message.find(from);
    if (at != std::string::npos && at <= std::string("unknown ").size())
      message.insert(at + from.size(), key + ".");
    else
      message = key + ": " + message;
    throw InvalidArgument(message);
  }
  spec.base_dir = base_dir;
  std::string why;
  if (!spec.IsValid(&why)) throw InvalidArgument(fmt::format("parameter '{}': {}", key, why));
  return spec;
}

void SetPose(Image& image, const geometry::Pose& X_WC, const head::JointState& joints) {
  ImageMetadata& meta = image.metadata();
  geometry::SetCameraPose(meta, X_WC);
  meta.has_joints = true;
  meta.joints.assign(joints.values().data(), joints.values().data() + joints.size());
  meta.joint_names = joints.shared_names();
}

}  // namespace

HwCameras::HwCameras()
    : joints_(AddInput<JointStateMessage>("joints")),
      left_(AddOutput<runtime::ImageMessage>("left")),
      right_(AddOutput<runtime::ImageMessage>("right")) {
  DeclareParam("scene", &scene_param_, internal::kSceneParamDoc).Path();
  DeclareParam("cameras", &cameras_,
               "{left: SOURCE, right: SOURCE}, each SOURCE {uri (required), calibration, "
               "calibration_index 0, fps 0, loop false, first 0, every 1} as "
               "hw::CameraSourceSpec documents; paths relative to the pipeline file")
      .Required();
  DeclareParam("max_skew_s", &max_skew_s_, "the most the two time stamps of a pair may differ")
      .Range(0.0, 3600.0)
      .Unit("s");
}

void HwCameras::Configured() {
  const internal::SceneRef scene = internal::SceneOf(*this, scene_param_);
  const std::string& path = scene.path;
  const nlohmann::json& cameras = cameras_;
  for (const auto& [key, value] : cameras.items()) {
    (void)value;
    if (key != "left" && key != "right") {
      throw InvalidArgument("parameter 'cameras': unknown camera '" + key +
                            "' (the head's eye cameras are left and right)");
    }
  }
  for (const char* eye : {"left", "right"}) {
    if (!cameras.contains(eye)) {
      throw InvalidArgument(std::string("parameter 'cameras': missing camera '") + eye + "'");
    }
  }
  const std::string base_dir = ResolvePath(".");
  left_spec_ = ReadSource(cameras["left"], "left", base_dir);
  right_spec_ = ReadSource(cameras["right"], "right", base_dir);
  scene_ = scene.scene;
  internal::RobotOf(*scene_, path);
}

void HwCameras::Start() {
  source_ = hw::OpenStereoSource(left_spec_, right_spec_, max_skew_s_);
  ended_ = false;
  pairs_ = 0;
  dropped_left_ = dropped_right_ = 0;
}

std::string HwCameras::Describe() const {
  return fmt::format("{} stereo pairs from {} and {}, {} + {} frames dropped (skew over {} s)",
                     pairs_, left_spec_.uri, right_spec_.uri, dropped_left_, dropped_right_,
                     max_skew_s_);
}

void HwCameras::Step(const runtime::StepContext& context) {
  if (ended_) return;
  std::optional<hw::StereoFrame> pair = source_->Grab();
  dropped_left_ = source_->dropped_left();
  dropped_right_ = source_->dropped_right();
  if (!pair) {
    ended_ = true;
    log::Info("hw.cameras '{}': the camera sources ended after {} pairs ({}, {})", name(), pairs_,
              left_spec_.uri, right_spec_.uri);
    return;
  }
  const scene::Robot& robot = *scene_->robot();
  head::JointState joints = robot.initial_joints;
  if (const JointStateMessage* state = joints_.get()) joints = state->positions;
  joints = robot.head.Arrange(joints);
  const std::array<geometry::Pose, 2> cameras = robot.head.CameraPoses(joints);
  // The step's time and a per-pair index, as sim.cameras stamps its frames.
  for (const auto& [image, X_WC] :
       {std::pair{pair->left, cameras[0]}, std::pair{pair->right, cameras[1]}}) {
    SetPose(*image, X_WC, joints);
    image->metadata().time = context.time;
    image->metadata().frame_index = pairs_;
  }
  ++pairs_;
  left_.Emit(runtime::ImageMessage{pair->left});
  right_.Emit(runtime::ImageMessage{pair->right});
}

void HwCameras::Stop() { source_.reset(); }

}  // namespace saccade::components
