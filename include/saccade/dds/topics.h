#pragma once
// saccade's messages on ROS 2 topics. A Writer publishes one saccade message type on a ROS
// topic as its ROS 2 type; a Reader subscribes and gives saccade messages back. The message
// types that cross, and what they become (docs/dds.md has the field-by-field mapping):
//
//   saccade message        ROS 2 type on the topic         also
//   image (ImageMessage)   sensor_msgs/Image               sensor_msgs/CameraInfo on the
//                                                          sibling camera_info topic;
//                                                          tf2_msgs/TFMessage world -> the
//                                                          camera's optical frame on /tf
//   head.joints            sensor_msgs/JointState          names pan, tilt, left, right;
//                                                          the targets as a JointState on
//                                                          the sibling joint_targets topic
//   head.command           sensor_msgs/JointState          positions, velocities
//   vision.target          geometry_msgs/PointStamped      frame "world"; only valid targets
//   mapping.map            sensor_msgs/PointCloud2         frame "world": the occupied voxels'
//                                                          centres (x, y, z, rgb by height);
//                                                          the inhibited places as a second
//                                                          PointCloud2 (x, y, z, strength,
//                                                          radius) on `<topic>/inhibited`
//   (the simulated clock)  rosgraph_msgs/Clock on /clock   ClockWriter, as Gazebo publishes it
//
// Images also go out JPEG- or PNG-compressed as sensor_msgs/CompressedImage on
// `<topic>/compressed` (image_transport's compressed plugin's name and format string), encoded
// only while a reader of it is matched: a best-effort reader with Cyclone's default
// configuration loses most raw images (a lost fragment loses the image), few compressed ones.
//
// Messages carry their capture time as header.stamp (builtin_interfaces/Time: sec, nanosec):
// simulated seconds from 0, or those plus an offset (TopicOptions::stamp_offset_ns, the wall
// clock at the start) that each writer announces and saccade's readers take off again.
// Frames are named "world" and "<camera>_optical" (OpenCV's camera frame: x right, y down,
// z forward, as ROS's optical frames).
//
// Loss and lateness are counted, never waited out unboundedly: Reader::Take waits at most its
// timeout and reports what it skipped (LinkStats). A writer or reader that goes away and comes
// back is matched again by DDS discovery; a reader sees the restart as a stamp going back and
// counts it.
//
// Thread-safety: one Writer or Reader is used by one thread at a time.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/dds/participant.h"
#include "saccade/dds/qos.h"
#include "saccade/runtime/message.h"

namespace saccade::dds {

/// Where a message type goes.
struct TopicOptions {
  std::string topic;  ///< fully qualified ROS topic (ResolveTopic), e.g. "/saccade/joint_states"
  Qos qos = Qos::Default();  ///< of the main topic (camera_info and tf: reliable, keep last)
  /// Images: where the camera poses go; joint states with a head
  /// (components::JointStateMessage::head): every link's pose, world -> root link and parent
  /// -> child link per joint ("" : none).
  std::string tf_topic = "/tf";
  /// Joint states with a head: where its URDF goes, once, as std_msgs/String (reliable,
  /// transient local, keep last 1, as robot_state_publisher's robot_description), so that a
  /// reader that comes later gets it ("" : none).
  std::string robot_description_topic;
  /// Joint states: where the head's targets go, as a JointState of the same stamp written
  /// just before it (positions: where each joint is heading, velocities: how fast that target
  /// moves), so that a reader knows whether the head has arrived exactly as the sender does
  /// (a joint state has no targets). "" : none.
  std::string targets_topic;
  /// Maps (mapping.map): where the places inhibition of return holds go, as a PointCloud2 of
  /// the same stamp written just before the map's (the pipeline's transport: `<topic>/inhibited`).
  /// A reader joins them to the map of that stamp. "" : none.
  std::string inhibited_topic;
  /// Images received: the frame index is round(stamp / frame_period_s) when > 0 (the
  /// sender's clock step), else a count of the frames received.
  double frame_period_s = 0.0;
  /// Head commands (sensor_msgs/JointState) only. A writer in lockstep announces it in its
  /// DDS user data ("saccade.lockstep=1;") and answers every step of its pipeline: with the
  /// step's command, or an empty JointState (no joint named) stamped with the step's time
  /// (Writer::MarkStep). A reader in lockstep waits, each step, for the message of the step's
  /// time from every matched writer in lockstep (Reader::WaitForStep); writers not in
  /// lockstep (a GUI, a ROS 2 tool) are never waited for. Empty JointStates are step marks,
  /// not commands, for every reader.
  bool lockstep = false;
  /// Added to every stamp written, in ns (`transport.stamps: wall`: the wall clock's time at
  /// the start, so that stamps are in the present); 0: simulated seconds from 0. A writer with
  /// an offset announces it in its DDS user data ("saccade.stamp_offset_ns=N;"); saccade's
  /// readers take each writer's offset off its stamps (exactly: whole ns), so that they see
  /// the sender's simulated time either way.
  int64_t stamp_offset_ns = 0;
  /// Images written: "jpeg" or "png" publishes a sensor_msgs/CompressedImage beside the raw
  /// image on `<topic>/compressed` (encoded only while a reader of it is matched); "" none.
  std::string compressed_format = "jpeg";
  /// JPEG quality of the compressed images, 1..100 (image_transport's default is 95).
  int jpeg_quality = 90;
};

/// What crossed a link, for reports.
struct LinkStats {
  int64_t messages = 0;    ///< written, or taken and handed over
  int64_t lost = 0;        ///< known lost: best-effort gaps and samples overwritten unread
  int64_t late = 0;        ///< Take calls whose wait ended without a new message
  int64_t restarts = 0;    ///< the sender's stamps went back (it restarted)
  int64_t incomplete = 0;  ///< images without camera info or pose, joint states without
                           ///< targets (handed over without them)
};

/// The saccade message types that have a ROS 2 form (MessageTraits names: "image", ...).
std::vector<std::string> SupportedMessageTypes();

/// The ROS 2 type a saccade message type is published as ("sensor_msgs/msg/Image"). Throws
/// InvalidArgument naming the type and the supported ones.
std::string RosTypeOf(const std::string& message_type);

/// The ROS 2 message definition of a type the writers produce ("sensor_msgs/msg/Image", ...), in
/// the form rosbag2 stores as an MCAP schema of encoding `ros2msg`: the type's fields as its
/// .msg file declares them, then each type it uses, after a line of 80 '=' and "MSG: pkg/Type".
/// Throws InvalidArgument for another type.
std::string RosMessageDefinition(const std::string& ros_type);

/// A message serialized as a Writer puts it on the wire (Writer::CreateSerializing): its ROS
/// topic, ROS 2 type ("sensor_msgs/msg/Image"), capture stamp (its header's, in ns; a
/// robot_description's: its joint state's) and bytes: the 4-byte encapsulation header (CDR,
/// little-endian), then XCDR1. Valid during the call.
struct SerializedMessage {
  const std::string& topic;
  const std::string& ros_type;
  int64_t stamp_ns;
  const uint8_t* data;
  std::size_t size;
};
using SerializedSink = std::function<void(const SerializedMessage&)>;

/// Publishes one saccade message type on one ROS topic.
class Writer {
 public:
  /// Throws InvalidArgument for an unsupported message type (naming the supported ones), a bad
  /// topic name or QoS; saccade::Error when Cyclone refuses (its reason included).
  static std::unique_ptr<Writer> Create(std::shared_ptr<Participant> participant,
                                        const std::string& message_type,
                                        const TopicOptions& options);
  /// A writer that hands each ROS 2 message to `sink`, serialized with the same conversion and
  /// the same serializer (Cyclone's) as the DDS writer, instead of publishing it (a recording:
  /// record/). Every topic counts as matched (CompressedImage included, unless
  /// compressed_format is ""); `lockstep` is ignored. Throws as Create.
  static std::unique_ptr<Writer> CreateSerializing(const std::string& message_type,
                                                   const TopicOptions& options,
                                                   SerializedSink sink);
  virtual ~Writer() = default;

  /// Publishes `message` (M must be the writer's type, else InvalidArgument). Does not block
  /// beyond Cyclone's reliable flow control (100 ms at most).
  template <runtime::Message M>
  void Write(const M& message) {
    CheckType(runtime::MessageName<M>());
    WriteErased(&message);
  }
  /// Publishes a message of the writer's type given by address.
  virtual void WriteErased(const void* message) = 0;
  /// A lockstep writer (TopicOptions::lockstep): marks its pipeline's step at `time`
  /// (seconds) done, writing an empty JointState stamped `time` unless a message stamped at
  /// or after it was written since the last mark. InvalidArgument for other writers.
  virtual void MarkStep(double time);
  /// Readers matched now.
  virtual int matched() const = 0;
  /// Waits until at least `count` readers match, at most `timeout_s`; true when they do.
  bool WaitForReaders(int count, double timeout_s) const;
  virtual const LinkStats& stats() const = 0;
  const std::string& message_type() const { return message_type_; }
  const std::string& topic() const { return topic_; }

 protected:
  Writer(std::string message_type, std::string topic)
      : message_type_(std::move(message_type)), topic_(std::move(topic)) {}
  void CheckType(const char* name) const;

 private:
  std::string message_type_;
  std::string topic_;
};

/// Publishes the simulated clock on /clock as rosgraph_msgs/Clock, as Gazebo does, for ROS 2
/// nodes run with `use_sim_time:=true` (their now() is the last clock received). QoS: reliable,
/// volatile, keep last 1, which rclcpp's ClockQoS subscription (best effort, keep last 1)
/// and reliable subscribers both match.
class ClockWriter {
 public:
  /// `topic` a fully qualified ROS topic; `stamp_offset_ns` as TopicOptions'. Throws as
  /// Writer::Create.
  static std::unique_ptr<ClockWriter> Create(std::shared_ptr<Participant> participant,
                                             const std::string& topic = "/clock",
                                             int64_t stamp_offset_ns = 0);
  virtual ~ClockWriter() = default;
  /// Publishes `time` (simulated seconds) plus the offset. Does not throw (logs a refusal).
  virtual void Publish(double time) = 0;
  /// Readers matched now.
  virtual int matched() const = 0;
};

/// Subscribes to one ROS topic and gives saccade messages of one type.
class Reader {
 public:
  /// Throws as Writer::Create.
  static std::unique_ptr<Reader> Create(std::shared_ptr<Participant> participant,
                                        const std::string& message_type,
                                        const TopicOptions& options);
  virtual ~Reader() = default;

  /// The newest message that arrived since the last call, waiting for one at most
  /// `timeout_s` (0: do not wait); nullptr when none came (counted late when it waited).
  /// Older messages that arrived in between are skipped and counted lost. The pointer holds
  /// a T of the reader's type (M must be it, else InvalidArgument).
  ///
  /// `up_to` (seconds, a pipeline stepping on the sender's stamps: runtime's clock.source):
  /// the newest message stamped at or before it; messages stamped after it are kept for a
  /// later call (and waiting ends when they arrive), so that a step takes the joints and the
  /// other eye's image of its own time even when the sender is steps ahead. Images are kept
  /// serialized and converted only when handed over, at most 16.
  template <runtime::Message M>
  std::shared_ptr<const M> Take(double timeout_s = 0.0,
                                double up_to = std::numeric_limits<double>::infinity()) {
    CheckType(runtime::MessageName<M>());
    return std::static_pointer_cast<const M>(TakeErased(timeout_s, up_to));
  }
  virtual std::shared_ptr<const void> TakeErased(double timeout_s, double up_to) = 0;
  /// A lockstep reader (TopicOptions::lockstep): waits until every matched writer in lockstep
  /// has sent, since the last Take, a message stamped at or after `time` (seconds, a
  /// microsecond's margin), at most `timeout_s`; a writer that goes away ends its wait. True
  /// when they did (or none is matched); false when the wait ran out (counted late). Other
  /// readers: true at once.
  virtual bool WaitForStep(double time, double timeout_s);
  /// Writers in lockstep matched now (0 for readers not in lockstep).
  virtual int lockstep_writers() { return 0; }
  /// Waits until a writer in lockstep matches, at most `timeout_s`; true when one does.
  bool WaitForLockstepWriter(double timeout_s);
  /// Writers matched now.
  virtual int matched() const = 0;
  /// Waits until at least `count` writers match, at most `timeout_s`; true when they do.
  bool WaitForWriters(int count, double timeout_s) const;
  virtual const LinkStats& stats() const = 0;
  const std::string& message_type() const { return message_type_; }
  const std::string& topic() const { return topic_; }

 protected:
  Reader(std::string message_type, std::string topic)
      : message_type_(std::move(message_type)), topic_(std::move(topic)) {}
  void CheckType(const char* name) const;

 private:
  std::string message_type_;
  std::string topic_;
};

/// The ROS 2 types of the messages the writers produce ("sensor_msgs/msg/Image", ...): those a
/// CdrWriter publishes and RosMessageDefinition knows.
std::vector<std::string> RosMessageTypes();

/// Publishes ROS 2 messages given serialized, as SerializedMessage holds them (a recording
/// played back as the robot: record/player.h): each is read into its type, checked whole,
/// and written as a Writer writes.
class CdrWriter {
 public:
  /// `ros_type` one of RosMessageTypes(), `topic` fully qualified. Throws InvalidArgument for
  /// another type, a bad topic or QoS; saccade::Error when Cyclone refuses.
  static std::unique_ptr<CdrWriter> Create(std::shared_ptr<Participant> participant,
                                           const std::string& ros_type, const std::string& topic,
                                           const Qos& qos);
  virtual ~CdrWriter() = default;
  /// Publishes the message of `size` bytes (encapsulation header, then CDR of either byte
  /// order). Throws InvalidArgument naming the topic and type when they are not one whole
  /// message of the type.
  virtual void Write(const uint8_t* data, std::size_t size) = 0;
  /// Readers matched now.
  virtual int matched() const = 0;
};

}  // namespace saccade::dds
