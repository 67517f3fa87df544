#pragma once
// The messages of the active-vision loop (seed Fig. 2: capture, perception, fixation, motors).
// Messages that refer to an image hold it by std::shared_ptr (DESIGN.md: in one process,
// images are shared, never copied); their JSON form carries the image's metadata only
// (camera, frame_index, time) and FromJson gives a null image: pixels never cross a text link.
//
// Units: SI and radians; points in the world frame W; boxes in pixels of their image
// (x, y of the top-left pixel, width, height), row 0 at the top.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/head/head_description.h"
#include "saccade/runtime/message.h"

namespace saccade::components {

/// The head's joints at `time` (sim.head's output, and a real head's): where the eye cameras
/// are and how fast they move (motion blur).
struct JointStateMessage {
  double time = 0.0;             ///< s
  head::JointState positions;    ///< rad
  head::JointState velocities;   ///< rad/s
  head::JointState targets;      ///< rad: where the motors are heading (clamped)
  bool arrived = true;           ///< every joint at rest on its target
  int64_t clamped_commands = 0;  ///< commands clamped to the joint limits so far
};

/// A joint command: a saccade (velocities zero) or smooth pursuit (the target moves at
/// `velocities` from `positions` at `time`). The receiver clamps it to its joint limits.
struct JointCommand {
  double time = 0.0;            ///< s, when it was issued
  head::JointState positions;   ///< rad
  head::JointState velocities;  ///< rad/s, zero for a saccade
  int64_t target_id = -1;       ///< the fixation target it serves (-1: none)
  bool pursuit() const;         ///< any velocity non-zero
};

/// A head driver's state beyond its joints (hw.head, hw/head_driver.h): the safety state,
/// faults and counters, for operators and the GUI.
struct HeadStatusMessage {
  double time = 0.0;            ///< s, the step's time
  std::string driver;           ///< "simulated", "dynamixel on /dev/ttyUSB0", ...
  head::JointState positions;   ///< rad, measured on the device
  head::JointState velocities;  ///< rad/s
  head::JointState targets;     ///< rad, last sent (the hold position when held)
  bool torque = false;
  bool holding = false;  ///< the watchdog stopped the head
  bool emergency_stopped = false;
  std::string fault;  ///< "" when none
  int64_t commands = 0;
  int64_t rejected_commands = 0;
  int64_t limited_commands = 0;
  int64_t watchdog_trips = 0;
  std::string last_limit;  ///< the last clamping or limiting, "" when none
  bool mirror = false;     ///< the device follows a virtual head (mirror mode)
};

/// Faces found in one image (vision.face_detector), rejected candidates included and flagged.
struct FacesMessage {
  std::shared_ptr<const Image> image;  ///< the image they were found in
  struct Face {
    cv::Rect box;
    int neighbors = 0;
    bool rejected = false;
    std::string reason;  ///< why it was rejected ("cat face", "no eyes"), "" when not
  };
  std::vector<Face> faces;  ///< largest first
};

/// One face seen by both eyes and triangulated (vision.stereo_faces).
struct FaceCandidate {
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();  ///< m, world
  cv::Rect left_box;
  cv::Rect right_box;
  double distance_m = 0.0;       ///< from the midpoint of the two camera centres
  double reprojection_px = 0.0;  ///< larger of the two
  double gap_m = 0.0;            ///< shortest distance between the rays
  double width_m = 0.0;          ///< physical width from the box and the depth
};

/// Every face both eyes see at one time, closest first.
struct CandidatesMessage {
  double time = 0.0;
  int64_t frame_index = 0;
  std::vector<FaceCandidate> candidates;
};

/// What attention chose to look at (vision.attention): a target with an id that changes only
/// when attention moves to another place, and the places inhibition of return suppresses.
struct SelectionMessage {
  double time = 0.0;
  int64_t frame_index = 0;
  bool valid = false;      ///< false: nothing to look at
  int64_t target_id = -1;  ///< 0, 1, 2, ... one per place attended
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();
  /// The target's boxes in this frame's images, when this frame's detections found it.
  bool boxes_fresh = false;
  cv::Rect left_box;
  cv::Rect right_box;
  bool fixating = false;  ///< the head is at rest with its fixation point on the target
  /// No face to look at for a while: p_W is the home point straight ahead of the head, so
  /// that the head looks around for faces (no boxes; not a face).
  bool exploring = false;
  double dwell_s = 0.0;                       ///< how long the target has been fixated
  std::vector<Eigen::Vector3d> suppressed_W;  ///< places inhibition of return suppresses
};

/// One eye's CamShift track of the selected target (vision.camshift).
struct TrackMessage {
  std::shared_ptr<const Image> image;
  int64_t target_id = -1;
  bool tracking = false;
  cv::Rect window;  ///< upright box of the track
  cv::Point2d center;
  bool reseeded = false;  ///< this frame (re)started the track from a detection
  std::string reason;     ///< why it is not tracking
};

/// The 3D point to fixate (vision.triangulate).
struct TargetMessage {
  double time = 0.0;
  int64_t frame_index = 0;
  bool valid = false;
  int64_t target_id = -1;
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();
  std::string source;  ///< "tracks" (both eyes' CamShift tracks) or "selection" (detections)
  double reprojection_px = 0.0;
  double gap_m = 0.0;
};

/// Registers every message type above with runtime::MessageRegistry::Global() (idempotent).
void RegisterMessages();

}  // namespace saccade::components

namespace saccade::runtime {

template <>
struct MessageTraits<components::JointStateMessage> {
  static constexpr const char* kName = "head.joints";
  static nlohmann::json ToJson(const components::JointStateMessage& m);
  static components::JointStateMessage FromJson(const nlohmann::json& j);
};

template <>
struct MessageTraits<components::JointCommand> {
  static constexpr const char* kName = "head.command";
  static nlohmann::json ToJson(const components::JointCommand& m);
  static components::JointCommand FromJson(const nlohmann::json& j);
};

template <>
struct MessageTraits<components::HeadStatusMessage> {
  static constexpr const char* kName = "head.status";
  static nlohmann::json ToJson(const components::HeadStatusMessage& m);
  static components::HeadStatusMessage FromJson(const nlohmann::json& j);
};

template <>
struct MessageTraits<components::FacesMessage> {
  static constexpr const char* kName = "vision.faces";
  static nlohmann::json ToJson(const components::FacesMessage& m);
  static components::FacesMessage FromJson(const nlohmann::json& j);
};

template <>
struct MessageTraits<components::CandidatesMessage> {
  static constexpr const char* kName = "vision.candidates";
  static nlohmann::json ToJson(const components::CandidatesMessage& m);
  static components::CandidatesMessage FromJson(const nlohmann::json& j);
};

template <>
struct MessageTraits<components::SelectionMessage> {
  static constexpr const char* kName = "vision.selection";
  static nlohmann::json ToJson(const components::SelectionMessage& m);
  static components::SelectionMessage FromJson(const nlohmann::json& j);
};

template <>
struct MessageTraits<components::TrackMessage> {
  static constexpr const char* kName = "vision.track";
  static nlohmann::json ToJson(const components::TrackMessage& m);
  static components::TrackMessage FromJson(const nlohmann::json& j);
};

template <>
struct MessageTraits<components::TargetMessage> {
  static constexpr const char* kName = "vision.target";
  static nlohmann::json ToJson(const components::TargetMessage& m);
  static components::TargetMessage FromJson(const nlohmann::json& j);
};

}  // namespace saccade::runtime
