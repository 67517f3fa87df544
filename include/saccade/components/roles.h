#pragma once
// The robot's roles: the typed interfaces through which the applications (the demo's report,
// the GUI) use the parts of a pipeline that stand for the robot, whatever implements them:
//
//   HeadRole        the head: sim.head (simulated motors), hw.head (a real head's driver)
//   EyeCamerasRole  the eye cameras: sim.cameras (rendered), hw.cameras (real cameras)
//
// A pipeline hands them out by type (runtime::Pipeline::FindRole<HeadRole>()): no lookup by
// class, no method found by its name, no JSON inside the process. Call them between steps, from
// the thread that runs the pipeline (as the components' methods).
#include <cstdint>
#include <optional>
#include <string>

#include "saccade/components/messages.h"
#include "saccade/core/error.h"
#include "saccade/render/renderer.h"
#include "saccade/runtime/component.h"
#include "saccade/scene/scene.h"

namespace saccade::components {

/// The robot's head.
class HeadRole {
 public:
  virtual ~HeadRole() = default;
  /// The joints now: positions, velocities, targets (measured on a real head).
  virtual JointStateMessage HeadState() = 0;
  /// A saccade or pursuit command, clamped to the joint limits (a real head's driver checks,
  /// clamps and limits it again). Throws Error when the command is refused (NaN, a fault, an
  /// emergency stop). Returns the state after it.
  virtual JointStateMessage Move(const JointCommand& command) = 0;
  /// Brakes every joint at its acceleration limit and holds where it stops.
  virtual void StopHead() = 0;
  /// Whether it has an emergency stop and faults to clear (a real head's driver).
  virtual bool has_emergency_stop() const { return false; }
  /// Holds and refuses every command until ClearFault. Throws Error without one.
  virtual void EmergencyStop() {
    throw Error("this head has no emergency stop (a simulated head)");
  }
  /// Clears an emergency stop or a fault. Throws Error without one.
  virtual void ClearFault() { throw Error("this head has no faults to clear (a simulated head)"); }
};

/// Frames delivered and dropped by real cameras.
struct CameraPairCounts {
  int64_t pairs = 0;
  int64_t dropped_left = 0;
  int64_t dropped_right = 0;
};

/// The robot's eye cameras.
class EyeCamerasRole {
 public:
  virtual ~EyeCamerasRole() = default;
  /// The scene whose robot carries the cameras (for rendered cameras, also what they see).
  virtual const scene::Scene& scene() const = 0;
  /// The renderer's options when the cameras are rendered (ground truth exists); nullptr for
  /// real cameras.
  virtual const render::RendererOptions* rendered() const { return nullptr; }
  /// Switches the rendered effects (the next step renders with them). Throws Error for real
  /// cameras.
  virtual void SetEffects(const render::EffectSwitches& effects) {
    (void)effects;
    throw Error("real cameras have no rendered effects to switch");
  }
  /// Pipelined capture: each step emits the frames rendered during the previous one, which
  /// overlaps rendering with the rest of the loop (sim.cameras' `pipelined`). Rendered cameras
  /// only; real ones capture on their own clock anyway. Call before the run starts.
  virtual void SetPipelined(bool on) { (void)on; }
  /// The camera whose raw colour filter array mosaic the image output `output` carries
  /// (sim.cameras' `<camera>_raw`, with `raw: true`); "" for a camera's own image and any
  /// other output. Recordings put such a mosaic on `<camera>/raw/image_raw`.
  virtual std::string RawMosaicCamera(const std::string& output) const {
    (void)output;
    return "";
  }
  /// Pairs delivered and frames dropped, for real cameras; nullopt for rendered ones.
  virtual std::optional<CameraPairCounts> pair_counts() const { return std::nullopt; }
  /// A line for people about the sources ("" for rendered cameras).
  virtual std::string Describe() const { return {}; }
};

/// Whether `component` stands for the robot (plays a role above).
inline bool IsRobotRole(const runtime::Component& component) {
  return dynamic_cast<const HeadRole*>(&component) != nullptr ||
         dynamic_cast<const EyeCamerasRole*>(&component) != nullptr;
}

}  // namespace saccade::components
