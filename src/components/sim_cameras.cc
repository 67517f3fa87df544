#include "saccade/components/sim_cameras.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>
#include <vector>

#include "components/internal_render_thread.h"
#include "components/internal_scene.h"
#include "saccade/core/error.h"

namespace saccade::components {

SimCameras::SimCameras()
    : joints_(AddInput<JointStateMessage>("joints")),
      controls_(AddInput<CameraControlsMessage>("controls")) {
  options_.cameras = {"left", "right"};
  DeclareParam("scene", &scene_param_, internal::kSceneParamDoc).Path();
  DeclareParam("cameras", &options_.cameras,
               "the scene's cameras to render, one image output each, named as the camera");
  DeclareParam("raw", &raw_,
               "also the raw colour filter array mosaic of each camera that has one (the "
               "scene's sensor: {color: {cfa: ...}}), as the output <camera>_raw (a Bayer "
               "image, before demosaicing; the colour image's metadata)");
  DeclareParam("distortion", &options_.distortion, "the calibrations' lens distortion");
  DeclareParam("noise", &options_.noise, "sensor noise, seeded per camera and frame");
  DeclareParam("motion_blur", &options_.motion_blur, "blur over each camera's exposure");
  DeclareParam("turn_blur", &options_.turn_blur,
               "motion blur of a turning camera (a saccade) from a few drawn instants seen "
               "through the turn, while the parallax and moving items stay within "
               "turn_blur_max_error_px; false: every sub-frame drawn");
  DeclareParam("turn_blur_max_error_px", &options_.turn_blur_max_error_px,
               "turn_blur's bound on how far a sub-frame may depart from drawing it")
      .Range(0.0, 1e6)
      .Unit("px");
  DeclareParam("msaa", &options_.msaa_samples, "multisample anti-aliasing: 0, 2, 4 or 8 samples")
      .Range(0, 8);
  DeclareParam("lod_max_error_px", &options_.lod_max_error_px,
               "level of detail: the largest screen error of a simplified model")
      .Range(0.0, 1e6)
      .Unit("px");
  DeclareParam("pipelined", &pipelined_,
               "render the next frame while the loop works on this one (one step older): always, "
               "never, or auto (with the real-time clock)")
      .Choices({"auto", "always", "never"});
}

void SimCameras::Configured() {
  const internal::SceneRef scene = internal::SceneOf(*this, scene_param_);
  const std::string& path = scene.path;
  std::string error;
  if (!options_.IsValid(&error)) throw InvalidArgument(error);
  scene_ = scene.scene;
  for (const std::string& camera : options_.cameras) {
    if (scene_->FindCamera(camera) == nullptr) {
      throw InvalidArgument("parameter 'cameras': scene '" + path + "' has no camera '" + camera +
                            "'");
    }
    outputs_.push_back(&AddOutput<runtime::ImageMessage>(camera));
  }
  raw_outputs_.assign(options_.cameras.size(), nullptr);
  if (raw_) AddRawOutputs(path);
}

void SimCameras::AddRawOutputs(const std::string& path) {
  std::string without;  // the cameras with no filter array
  for (std::size_t i = 0; i < options_.cameras.size(); ++i) {
    const std::string& camera = options_.cameras[i];
    if (scene_->FindCamera(camera)->sensor.color.cfa == scene::CfaPattern::kNone) {
      without += (without.empty() ? "" : ", ") + camera;
      continue;
    }
    const std::string name = RawOutputName(camera);
    if (FindOutput(name) != nullptr) {
      throw InvalidArgument(
          fmt::format("parameter 'raw': the raw output of camera '{}', '{}', is also the name "
                      "of a camera of 'cameras'",
                      camera, name));
    }
    raw_outputs_[i] = &AddOutput<runtime::ImageMessage>(name);
  }
  if (std::all_of(raw_outputs_.begin(), raw_outputs_.end(),
                  [](const auto* output) { return output == nullptr; })) {
    throw InvalidArgument(fmt::format(
        "parameter 'raw': no camera of 'cameras' ({}) in scene '{}' has a colour filter array, "
        "so none has a raw mosaic; give a camera sensor: {{color: {{cfa: rggb}}}} (or bggr, "
        "gbrg, grbg), or set raw: false",
        without, path));
  }
}

std::string SimCameras::RawMosaicCamera(const std::string& output) const {
  for (std::size_t i = 0; i < raw_outputs_.size(); ++i) {
    if (raw_outputs_[i] != nullptr && raw_outputs_[i]->name() == output) return options_.cameras[i];
  }
  return "";
}

SimCameras::~SimCameras() { Stop(); }

void SimCameras::Start() {
  thread_ = std::make_unique<internal::RenderThread>();
  try {
    thread_->Post([this] { renderer_ = render::MakeRenderer(*scene_, options_); }).get();
  } catch (...) {
    thread_.reset();
    throw;
  }
}

void SimCameras::SetEffects(const render::EffectSwitches& effects) {
  if (render::EffectSwitches::Of(options_) == effects) return;
  effects.ApplyTo(&options_);
  options_changed_ = true;
}

void SimCameras::Step(const runtime::StepContext& context) {
  const std::function<void()>* while_waiting = context.while_waiting;
  std::vector<render::Frame> frames;
  if (in_flight_) {
    // The previous step's frames (pipelined): this step emits them.
    std::future<std::vector<render::Frame>> previous = std::move(*in_flight_);
    in_flight_.reset();
    frames = internal::Await(std::move(previous), while_waiting);
  }
  if (options_changed_) {
    // Nothing is in flight now: the frames above were drawn with the old effects and go out
    // with this step's.
    const render::EffectSwitches effects = render::EffectSwitches::Of(options_);
    internal::Await(thread_->Post([this, effects] { renderer_->SetEffects(effects); }),
                    while_waiting);
    options_changed_ = false;
  }
  scene::SceneState state = scene_->InitialState();
  state.time = context.time;
  if (const JointStateMessage* joints = joints_.get()) {
    state.joints = joints->positions;
    state.joint_velocities = joints->velocities;
  }
  state.camera_controls = camera_controls_;  // commands of earlier steps
  TakeControls();
  const int64_t frame_index = context.step;
  auto render = [this, state = std::move(state), frame_index] {
    return renderer_->Render(state, frame_index);
  };
  const bool pipelined = pipelined_ == "always" || (pipelined_ == "auto" && context.realtime);
  if (pipelined) {
    in_flight_ = thread_->Post(std::move(render));
  } else {
    frames = internal::Await(thread_->Post(std::move(render)), while_waiting);
  }
  for (std::size_t i = 0; i < frames.size() && i < outputs_.size(); ++i) {
    outputs_[i]->Emit(runtime::ImageMessage{frames[i].color});
    if (raw_outputs_[i] != nullptr && frames[i].raw) {
      raw_outputs_[i]->Emit(runtime::ImageMessage{frames[i].raw});
    }
  }
}

void SimCameras::TakeControls() {
  const CameraControlsMessage* message = controls_.get();
  if (message == nullptr || !controls_.fresh()) return;
  std::map<std::string, scene::CameraControls> next = camera_controls_;
  for (const CameraCommand& command : message->commands) {
    std::vector<std::string> names;
    if (command.camera == "all") {
      for (const scene::CameraSpec& camera : scene_->cameras()) names.push_back(camera.name);
    } else if (scene_->FindCamera(command.camera) == nullptr) {
      std::string known;
      for (const scene::CameraSpec& camera : scene_->cameras()) {
        known += (known.empty() ? "" : ", ") + camera.name;
      }
      throw InvalidArgument(
          fmt::format("{}: input 'controls': no camera '{}' in the scene (it has: {}; or \"all\")",
                      name(), command.camera, known));
    } else {
      names.push_back(command.camera);
    }
    const scene::CameraControls commanded{command.exposure_s, command.gain_db, command.focus_m};
    commanded.Validate(fmt::format("{}: input 'controls': camera '{}'", name(), command.camera));
    for (const std::string& camera : names) {
      scene::CameraControls& controls = next[camera];
      if (commanded.exposure_s) controls.exposure_s = commanded.exposure_s;
      if (commanded.gain_db) controls.gain_db = commanded.gain_db;
      if (commanded.focus_m) controls.focus_m = commanded.focus_m;
    }
  }
  camera_controls_ = std::move(next);
}

void SimCameras::Stop() {
  if (!thread_) return;
  if (in_flight_) {
    in_flight_->wait();  // a frame nobody will take (its error too)
    in_flight_.reset();
  }
  thread_->Post([this] { renderer_.reset(); }).wait();
  thread_.reset();
}

}  // namespace saccade::components
