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
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/geometry/json.h"
#include "saccade/head/head_description.h"
#include "saccade/head/head_model.h"
#include "saccade/head/json.h"
#include "saccade/runtime/message.h"
#include "saccade/vision/dense_stereo.h"
#include "saccade/vision/json.h"

namespace saccade::mapping {
class WorldMap;
class Inhibition3d;
}  // namespace saccade::mapping

namespace saccade::components {

/// The head's joints at `time` (sim.head's output, and a real head's): where the eye cameras
/// are and how fast they move (motion blur).
struct JointStateMessage {
  double time = 0.0;                   ///< s
  head::JointState positions;          ///< rad
  head::JointState velocities;         ///< rad/s
  head::JointState targets;            ///< rad: where the motors are heading (clamped)
  head::JointState target_velocities;  ///< rad/s: how fast the targets move (pursuit), or 0
  bool arrived = true;                 ///< every joint on its target, in position and velocity
  int64_t clamped_commands = 0;        ///< commands clamped to the joint limits so far
  /// The head these are the joints of (its tree and URDF: DDS publishes robot_description and
  /// every link's TF from it), or null (joints received from another process). Not in JSON.
  std::shared_ptr<const head::HeadModel> head;
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

/// A command of one camera's controls (scene/camera_controls.h): each absent value unchanged.
struct CameraCommand {
  std::string camera;                ///< a camera's name, or "all"
  std::optional<double> exposure_s;  ///< s, in (0, 1]
  std::optional<double> gain_db;     ///< dB, in [0, 48]
  std::optional<double> focus_m;     ///< m, > 0
};

/// Commands of the cameras' exposure, gain and focus (camera.auto_exposure,
/// camera.accommodation; sim.cameras' `controls` input applies them to the next step's
/// frames, as a real camera takes a new exposure at the next frame).
struct CameraControlsMessage {
  double time = 0.0;                    ///< s, when they were issued
  std::vector<CameraCommand> commands;  ///< in order: a later value replaces an earlier one
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

/// Dense stereo depth of one image pair (vision.dense_stereo, vision/dense_stereo.h): depth in
/// the rectified left camera, its confidence and the rectification. Its JSON form carries the
/// left image's metadata and the figures; FromJson gives a null `stereo` (no pixels in text).
struct DepthMessage {
  double time = 0.0;
  int64_t frame_index = 0;
  std::shared_ptr<const Image> left;                  ///< the left image it was computed from
  std::shared_ptr<const vision::StereoDepth> stereo;  ///< not in JSON
  double matched = 0.0;     ///< share of the rectified view's pixels with a depth
  double baseline_m = 0.0;  ///< of the pair
  double focal_px = 0.0;    ///< of the rectified camera
};

/// A place inhibition of return holds (seed 7.2), anchored to the world: the head does not look
/// within radius_m of p_W while its strength lasts.
struct InhibitedPlace {
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();  ///< m, world
  double radius_m = 0.0;
  double strength = 0.0;  ///< 1 when fixated, decaying as exp(-t / time constant) after
};

/// The map the head has built of the world (mapping.world_map, issue 44): the centres of its
/// occupied voxels and the places inhibition of return holds, at one step. DDS publishes the
/// points as sensor_msgs/PointCloud2 (frame "world"); the GUI draws them growing. In one
/// process it carries the map itself too (free and unknown space, which novelty is made of) and
/// the inhibition of return, as snapshots that later fusions leave as they are; neither is in
/// JSON or on DDS, where they arrive null.
struct MapMessage {
  double time = 0.0;
  int64_t frame_index = 0;
  double resolution_m = 0.0;                         ///< voxel edge
  std::vector<Eigen::Vector3d> occupied_W;           ///< m, world: occupied voxels' centres
  std::vector<InhibitedPlace> inhibited;             ///< strongest first
  int64_t fused = 0;                                 ///< depth images fused so far
  std::shared_ptr<const mapping::WorldMap> map;      ///< not in JSON or on DDS
  std::shared_ptr<const mapping::Inhibition3d> ior;  ///< not in JSON or on DDS
};

/// Registers every message type above with runtime::MessageRegistry::Global() (idempotent).
void RegisterMessages();

}  // namespace saccade::components

// Each message lists its fields once; its JSON form follows (runtime/message.h). The codecs
// of the fields' types: core/json_codec.h (numbers, strings, lists, images), head/json.h
// (joints), geometry/json.h (points), vision/json.h (boxes, image points).
namespace saccade {

template <>
struct JsonCodec<components::FacesMessage::Face> : JsonObjectCodec<components::FacesMessage::Face> {
  using T = components::FacesMessage::Face;
  static constexpr auto kFields =
      std::make_tuple(JsonField("box", &T::box), JsonField("neighbors", &T::neighbors),
                      JsonField("rejected", &T::rejected), JsonField("reason", &T::reason));
};

template <>
struct JsonCodec<components::InhibitedPlace> : JsonObjectCodec<components::InhibitedPlace> {
  using T = components::InhibitedPlace;
  static constexpr auto kFields =
      std::make_tuple(JsonField("p_W", &T::p_W), JsonField("radius_m", &T::radius_m),
                      JsonField("strength", &T::strength));
};

template <>
struct JsonCodec<components::CameraCommand> : JsonObjectCodec<components::CameraCommand> {
  using T = components::CameraCommand;
  static constexpr auto kFields =
      std::make_tuple(JsonField("camera", &T::camera), JsonField("exposure_s", &T::exposure_s),
                      JsonField("gain_db", &T::gain_db), JsonField("focus_m", &T::focus_m));
};

template <>
struct JsonCodec<components::FaceCandidate> : JsonObjectCodec<components::FaceCandidate> {
  using T = components::FaceCandidate;
  static constexpr auto kFields = std::make_tuple(
      JsonField("p_W", &T::p_W), JsonField("left_box", &T::left_box),
      JsonField("right_box", &T::right_box), JsonField("distance_m", &T::distance_m),
      JsonField("reprojection_px", &T::reprojection_px), JsonField("gap_m", &T::gap_m),
      JsonField("width_m", &T::width_m));
};

}  // namespace saccade

namespace saccade::runtime {

template <>
struct MessageTraits<components::JointStateMessage> : FieldMessage<components::JointStateMessage> {
  using T = components::JointStateMessage;
  static constexpr const char* kName = "head.joints";
  static constexpr auto kFields = std::make_tuple(
      JsonField("time", &T::time), JsonField("positions", &T::positions),
      JsonField("velocities", &T::velocities), JsonField("targets", &T::targets),
      JsonField("target_velocities", &T::target_velocities), JsonField("arrived", &T::arrived),
      JsonField("clamped_commands", &T::clamped_commands));
};

template <>
struct MessageTraits<components::JointCommand> : FieldMessage<components::JointCommand> {
  using T = components::JointCommand;
  static constexpr const char* kName = "head.command";
  static constexpr auto kFields = std::make_tuple(
      JsonField("time", &T::time), JsonField("positions", &T::positions),
      JsonField("velocities", &T::velocities), JsonField("target_id", &T::target_id));
};

template <>
struct MessageTraits<components::CameraControlsMessage>
    : FieldMessage<components::CameraControlsMessage> {
  using T = components::CameraControlsMessage;
  static constexpr const char* kName = "camera.controls";
  static constexpr auto kFields =
      std::make_tuple(JsonField("time", &T::time), JsonField("commands", &T::commands));
};

template <>
struct MessageTraits<components::HeadStatusMessage> : FieldMessage<components::HeadStatusMessage> {
  using T = components::HeadStatusMessage;
  static constexpr const char* kName = "head.status";
  static constexpr auto kFields = std::make_tuple(
      JsonField("time", &T::time), JsonField("driver", &T::driver),
      JsonField("positions", &T::positions), JsonField("velocities", &T::velocities),
      JsonField("targets", &T::targets), JsonField("torque", &T::torque),
      JsonField("holding", &T::holding), JsonField("emergency_stopped", &T::emergency_stopped),
      JsonField("fault", &T::fault), JsonField("commands", &T::commands),
      JsonField("rejected_commands", &T::rejected_commands),
      JsonField("limited_commands", &T::limited_commands),
      JsonField("watchdog_trips", &T::watchdog_trips), JsonField("last_limit", &T::last_limit),
      JsonField("mirror", &T::mirror));
};

template <>
struct MessageTraits<components::FacesMessage> : FieldMessage<components::FacesMessage> {
  using T = components::FacesMessage;
  static constexpr const char* kName = "vision.faces";
  static constexpr auto kFields =
      std::make_tuple(JsonField("image", &T::image), JsonField("faces", &T::faces));
};

template <>
struct MessageTraits<components::CandidatesMessage> : FieldMessage<components::CandidatesMessage> {
  using T = components::CandidatesMessage;
  static constexpr const char* kName = "vision.candidates";
  static constexpr auto kFields =
      std::make_tuple(JsonField("time", &T::time), JsonField("frame_index", &T::frame_index),
                      JsonField("candidates", &T::candidates));
};

template <>
struct MessageTraits<components::SelectionMessage> : FieldMessage<components::SelectionMessage> {
  using T = components::SelectionMessage;
  static constexpr const char* kName = "vision.selection";
  static constexpr auto kFields = std::make_tuple(
      JsonField("time", &T::time), JsonField("frame_index", &T::frame_index),
      JsonField("valid", &T::valid), JsonField("target_id", &T::target_id),
      JsonField("p_W", &T::p_W), JsonField("boxes_fresh", &T::boxes_fresh),
      JsonField("left_box", &T::left_box), JsonField("right_box", &T::right_box),
      JsonField("fixating", &T::fixating), JsonField("exploring", &T::exploring),
      JsonField("dwell_s", &T::dwell_s), JsonField("suppressed_W", &T::suppressed_W));
};

template <>
struct MessageTraits<components::TrackMessage> : FieldMessage<components::TrackMessage> {
  using T = components::TrackMessage;
  static constexpr const char* kName = "vision.track";
  static constexpr auto kFields =
      std::make_tuple(JsonField("image", &T::image), JsonField("target_id", &T::target_id),
                      JsonField("tracking", &T::tracking), JsonField("window", &T::window),
                      JsonField("center", &T::center), JsonField("reseeded", &T::reseeded),
                      JsonField("reason", &T::reason));
};

template <>
struct MessageTraits<components::TargetMessage> : FieldMessage<components::TargetMessage> {
  using T = components::TargetMessage;
  static constexpr const char* kName = "vision.target";
  static constexpr auto kFields = std::make_tuple(
      JsonField("time", &T::time), JsonField("frame_index", &T::frame_index),
      JsonField("valid", &T::valid), JsonField("target_id", &T::target_id),
      JsonField("p_W", &T::p_W), JsonField("source", &T::source),
      JsonField("reprojection_px", &T::reprojection_px), JsonField("gap_m", &T::gap_m));
};

template <>
struct MessageTraits<components::DepthMessage> : FieldMessage<components::DepthMessage> {
  using T = components::DepthMessage;
  static constexpr const char* kName = "vision.depth";
  static constexpr auto kFields =
      std::make_tuple(JsonField("time", &T::time), JsonField("frame_index", &T::frame_index),
                      JsonField("left", &T::left), JsonField("matched", &T::matched),
                      JsonField("baseline_m", &T::baseline_m), JsonField("focal_px", &T::focal_px));
};

template <>
struct MessageTraits<components::MapMessage> : FieldMessage<components::MapMessage> {
  using T = components::MapMessage;
  static constexpr const char* kName = "mapping.map";
  static constexpr auto kFields = std::make_tuple(
      JsonField("time", &T::time), JsonField("frame_index", &T::frame_index),
      JsonField("resolution_m", &T::resolution_m), JsonField("occupied_W", &T::occupied_W),
      JsonField("inhibited", &T::inhibited), JsonField("fused", &T::fused));
};

}  // namespace saccade::runtime
