#pragma once
// sim.cameras -- renders the scene's cameras (seed: cameraCapture through the FBO), one image
//   output per camera of its `cameras` parameter.
//   inputs:  joints (head.joints, optional): the head's state at this step's time; connect
//            it from sim.head with delay 1. Without it, the scene's initial joints.
//            controls (camera.controls, optional): exposure, gain and focus commands
//            (camera.auto_exposure, camera.accommodation). A command received in step t
//            applies from the frame of step t + 1 on (a real camera's latency: the exposure
//            under way is not changed; with the usual `delay: 1` connection a command sent in
//            step t reaches frame t + 2) and holds until another replaces it; "all" commands
//            every camera of the scene. An unknown camera or a value out of range is an error
//            naming the component. Without commands, the file's values.
//   outputs: <camera> (runtime.image) per camera, shared; frame index = step. The metadata
//            carries the exposure, gain and focus the frame was taken with.
//            <camera>_raw (runtime.image) with `raw: true`, per camera that has a colour filter
//            array (its scene sensor's color: {cfa: ...}): Frame::raw, the Bayer mosaic
//            (bayer_rggb8, ...: one 8-bit sample a pixel, white balanced, before demosaicing
//            and the tone curve) of which <camera> is the demosaiced image, with its metadata;
//            emitted just after <camera>. A camera without a filter has no mosaic and no raw
//            output; `raw: true` where none of `cameras` has one is an error naming them.
//   The renderer lives on a thread of its own (its GL context current there). Pipelined
//   capture (`pipelined`: always, or auto with the real-time clock): each step hands this
//   step's state to that thread and emits the frames of the previous step's, which rendered
//   while the rest of the loop worked; the images are one step older (their capture time says
//   so), and the first step emits none. A render's error surfaces in the step that takes its
//   frames. While a step waits for frames it calls StepContext::while_waiting (a live GUI
//   takes its commands meanwhile).
// Parameters: declared in the constructor (docs/components.md lists them).
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saccade/components/messages.h"
#include "saccade/components/roles.h"
#include "saccade/render/renderer.h"
#include "saccade/runtime/component.h"
#include "saccade/scene/scene.h"

namespace saccade::components {

namespace internal {
class RenderThread;
}

class SimCameras : public runtime::Component, public EyeCamerasRole {
 public:
  SimCameras();
  ~SimCameras() override;
  void Start() override;
  void Step(const runtime::StepContext& context) override;
  void Stop() override;
  bool thread_affine() const override { return true; }  // while_waiting on the loop's thread

  const scene::Scene& scene() const override { return *scene_; }
  /// Switches the scene's effects (the GUI's toggles); the next Step renders with them
  /// (Renderer::SetEffects). Call from the thread that runs the pipeline (while_waiting
  /// included).
  void SetEffects(const render::EffectSwitches& effects) override;
  void SetPipelined(bool on) override { pipelined_ = on ? "always" : "never"; }
  std::string RawMosaicCamera(const std::string& output) const override;
  const render::RendererOptions& options() const { return options_; }
  const render::RendererOptions* rendered() const override { return &options_; }

 protected:
  void Configured() override;

 private:
  /// The output that carries `camera`'s raw mosaic (`raw`): "<camera>_raw".
  static std::string RawOutputName(const std::string& camera) { return camera + "_raw"; }
  // Adds the raw outputs (`raw`); InvalidArgument when no camera has a filter array.
  void AddRawOutputs(const std::string& path);
  // Merges this step's commands into camera_controls_ (they apply from the next step).
  void TakeControls();

  std::string scene_param_;
  runtime::Input<JointStateMessage>& joints_;
  runtime::Input<CameraControlsMessage>& controls_;
  // The commands in force (scene::SceneState::camera_controls), by camera name.
  std::map<std::string, scene::CameraControls> camera_controls_;
  std::vector<runtime::Output<runtime::ImageMessage>*> outputs_;
  // Per camera of options_.cameras: its raw mosaic's output, nullptr without one.
  std::vector<runtime::Output<runtime::ImageMessage>*> raw_outputs_;
  bool raw_ = false;
  std::shared_ptr<const scene::Scene> scene_;
  render::RendererOptions options_;
  std::unique_ptr<internal::RenderThread> thread_;                    // owns renderer_'s GL context
  std::unique_ptr<render::Renderer> renderer_;                        // used on thread_ only
  std::optional<std::future<std::vector<render::Frame>>> in_flight_;  // pipelined
  std::string pipelined_ = "auto";
  bool options_changed_ = false;
};

}  // namespace saccade::components
